// Exit codes and the one-line error report every app prints.
#pragma once

#include <exception>

namespace i20::app {

enum ExitCode : int {
  kOk = 0,
  kFailure = 1,       // link or card failure (timeout, CRC, card error)
  kBadInput = 2,      // bad arguments, files or values: nothing was sent
  kRefused = 3,       // a safety rule refused the write: nothing was sent
  kCardState = 4,     // verify failed or the card may be left in a special mode
  kFaultsRemain = 5,  // clear-faults: faults could not be cleared
  kInterrupted = 130,
};

// Prints "PROGRAM: error: MESSAGE" (one line) to stderr and returns the exit code for
// the exception. Call from a catch (...) block.
int report_current_exception(const char* program);

}  // namespace i20::app
