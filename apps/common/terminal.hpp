// SPDX-License-Identifier: GPL-2.0-or-later
// What the apps say on the terminal around a stop: the acknowledgement of a stop signal that
// arrives while the card is being restored or settled (ops::Session owns the signals), and
// the note that stdout or stderr went away before the report was complete.
#pragma once

#include "ops/core/cancel.hpp"

namespace i20::app {

// "PROGRAM: restoring NVKQP; the card settles in a moment", in one write(2) built by the main
// flow: it still reaches a terminal when std::cerr has failed before.
ops::Cancel::Acknowledge stop_acknowledgement(const char* program);

// The program's exit code once stdout is flushed: `code`, or 6 (output lost) when something
// written to stdout did not arrive (a full disk, the reader closed the pipe) and the command
// had otherwise succeeded; says so on stderr, once, if stderr still works. The card was
// settled before: a lost stdout changes nothing on it, but a report that did not land is
// not a success.
int finish_output(const char* program, int code);

// Throws OutputError when stdout has failed: long-running commands (watch) call it after
// each write, so they end when their reader goes away instead of polling on unread.
void require_stdout();

}  // namespace i20::app
