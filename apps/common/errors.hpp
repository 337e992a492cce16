// SPDX-License-Identifier: GPL-2.0-or-later
// The one-line error report every app prints, and the exit codes (lib/ops/outcome.hpp owns
// the map; these names are the apps' spelling of it).
#pragma once

#include "ops/outcome.hpp"
#include "parse_error.hpp"

namespace i20::app {

enum ExitCode : int {
  kOk = ops::kExitOk,
  kFailure = ops::kExitFailed,             // failed before anything was written (card not reached)
  kBadInput = ops::kExitBadInput,          // bad arguments, files or values: nothing was sent
  kRefused = ops::kExitRefused,            // a safety rule refused: nothing was written
  kCardState = ops::kExitUncertain,        // state uncertain or rolled back: cells named
  kFaultsRemain = ops::kExitFaultsRemain,  // clear-faults: faults could not be cleared
  kInterrupted = ops::kExitInterrupted,
};

// Prints "PROGRAM: LABEL: MESSAGE" (one line) to stderr and returns the exit code for the
// exception. Call from a catch (...) block.
int report_current_exception(const char* program);

}  // namespace i20::app
