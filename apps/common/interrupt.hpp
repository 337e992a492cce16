// SPDX-License-Identifier: GPL-2.0-or-later
// Stop requests: SIGINT (Ctrl-C), SIGTERM (kill, systemd, timeout(1)) and SIGHUP (the ssh
// session or terminal went away) all ask the same thing, through one ops::StopRequest that
// every use case polls between exchanges: stop before the next write, restore what was
// written, verify, leave NV access and RPC memory mode, report, exit 130.
//
// The handler only sets that request (lock-free atomics: async-signal-safe). It never ends
// the process: a signal that arrives while the tool restores or settles the card is answered
// by the main flow on stderr ("i20: restoring NVKQP; the card settles in a moment"). Only
// SIGKILL (kill -9) or SIGQUIT (Ctrl-\) end it at once; the next command then finds the card
// in the mode it was left in and switches it off (ops::Card::open).
//
// SIGPIPE is ignored: a closed stdout or stderr (`i20 ... | head -1`, a terminal that went
// away) makes writes fail, which the apps notice at the end (output_failed), after the card
// is settled, instead of the process dying in the middle of a write.
#pragma once

#include <atomic>

#include "ops/cancel.hpp"

namespace i20::app {

// Installs the handlers (idempotent) and returns the cancel token they set. `program` names
// the acknowledgements on stderr; the first call that gives one sets it.
ops::Cancel install_interrupt_handler(const char* program = nullptr);
bool interrupted();

// True when something written to stdout or stderr did not arrive (the reader closed the
// pipe, the terminal went away); says so on stderr once if stderr still works.
bool output_failed(const char* program);

}  // namespace i20::app
