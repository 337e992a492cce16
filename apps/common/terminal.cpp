// SPDX-License-Identifier: GPL-2.0-or-later
#include "terminal.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include "error/error.hpp"
#include "ops/core/outcome.hpp"

namespace i20::app {

ops::Cancel::Acknowledge stop_acknowledgement(const char* program) {
  return [program](const std::string& doing) {
    const std::string line = std::string(program) + ": " + doing + "; the card settles in a moment\n";
    [[maybe_unused]] const auto n = ::write(STDERR_FILENO, line.data(), line.size());
  };
}

namespace {

// Why stdout failed, or "" while it works. fflush reports the system's reason; a stream
// already in error (an earlier write failed) keeps only the fact.
std::string stdout_failure() {
  std::cout.flush();
  errno = 0;
  const bool flushed = std::fflush(stdout) == 0;
  if (flushed && std::cout.good() && !std::ferror(stdout)) return {};
  const int error = flushed ? 0 : errno;
  return error != 0 ? std::string(std::strerror(error))
                    : std::string("a write failed (disk full, or its reader went away)");
}

}  // namespace

int finish_output(const char* program, int code) {
  const std::string why = stdout_failure();
  std::cerr.flush();
  // Exit 6 was already explained by whoever found the lost output (often stdout itself).
  if (why.empty() || code == ops::kExitOutputLost) return code;
  const std::string line = std::string(program) + ": error: standard output was not written in full: " + why +
                           (code == ops::kExitOk ? "" : " (the exit code is the command's own outcome)") +
                           "\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, line.data(), line.size());
  return code == ops::kExitOk ? ops::kExitOutputLost : code;
}

void require_stdout() {
  if (const std::string why = stdout_failure(); !why.empty())
    throw OutputError("standard output was not written in full: " + why);
}

}  // namespace i20::app
