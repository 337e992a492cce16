// SPDX-License-Identifier: GPL-2.0-or-later
// What the apps say on the terminal around a stop: the acknowledgement of a stop signal that
// arrives while the card is being restored or settled (ops::Session owns the signals), and
// the note that stdout or stderr went away before the report was complete.
#pragma once

#include "ops/cancel.hpp"

namespace i20::app {

// "PROGRAM: restoring NVKQP; the card settles in a moment", in one write(2) built by the main
// flow: it still reaches a terminal when std::cerr has failed before.
ops::Cancel::Acknowledge stop_acknowledgement(const char* program);

// True when something written to stdout or stderr did not arrive (the reader closed the
// pipe, the terminal went away); says so on stderr once if stderr still works.
bool output_failed(const char* program);

}  // namespace i20::app
