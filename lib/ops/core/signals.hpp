// SPDX-License-Identifier: GPL-2.0-or-later
// Stop signals, owned by ops::Session: SIGINT (Ctrl-C), SIGTERM (kill, systemd, timeout(1))
// and SIGHUP (the ssh session or terminal went away) all ask the same thing, through one
// StopRequest that every use case polls between exchanges: stop before the next write,
// restore what was written, verify, leave NV access and RPC memory mode, report, exit 130.
//
// The handler only sets that request (lock-free atomics: async-signal-safe). It never ends
// the process: a signal that arrives while the tool restores or settles the card is answered
// by the main flow (Cancel::acknowledge: "restoring NVKQP; the card settles in a moment").
// Only SIGKILL (kill -9) or SIGQUIT (Ctrl-\) end it at once; the next command then finds the
// card in the mode it was left in and switches it off (ops::Amp::open).
//
// SIGTSTP (Ctrl-Z) waits while the card is in NV access or RPC memory mode and stops the
// process once the mode is left (device/suspend_hold.hpp).
//
// SIGPIPE is ignored: a closed stdout or stderr (`i20 ... | head -1`, a terminal that went
// away) makes writes fail, which the apps notice at the end, after the card is settled,
// instead of the process dying in the middle of a write; a long-running command (watch)
// checks its output after each write and ends (exit 6) when the reader is gone.
#pragma once

#include <chrono>
#include <functional>

#include "ops/core/cancel.hpp"

namespace i20::ops {

// Installs the handlers (idempotent: a program calls it as early as it can, the Session
// again) and returns the process's one stop request, which the handlers set.
StopRequest& install_stop_signals();
// True once SIGINT, SIGTERM or SIGHUP arrived (false before the handlers are installed).
bool stop_requested();

// Sleeps until `t` in slices of timing::kStopPollSlice, so Ctrl-C (or whatever `done` says,
// a watch's --duration) ends a wait between samples promptly. False when `done` turned true
// before `t`.
bool sleep_until(std::chrono::steady_clock::time_point t, const std::function<bool()>& done);

}  // namespace i20::ops
