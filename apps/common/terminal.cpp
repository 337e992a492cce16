// SPDX-License-Identifier: GPL-2.0-or-later
#include "terminal.hpp"

#include <unistd.h>

#include <cstdio>
#include <iostream>
#include <string>

namespace i20::app {

ops::Cancel::Acknowledge stop_acknowledgement(const char* program) {
  return [program](const std::string& doing) {
    const std::string line = std::string(program) + ": " + doing + "; the card settles in a moment\n";
    [[maybe_unused]] const auto n = ::write(STDERR_FILENO, line.data(), line.size());
  };
}

bool output_failed(const char* program) {
  std::cout.flush();
  std::cerr.flush();
  if (std::cout.good() && std::cerr.good() && std::fflush(stdout) == 0 && !std::ferror(stdout)) return false;
  const std::string line = std::string(program) +
                           ": note: standard output or error was closed before the report was complete "
                           "(the card was settled first; the exit code is the command's outcome)\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, line.data(), line.size());
  return true;
}

}  // namespace i20::app
