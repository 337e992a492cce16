// SPDX-License-Identifier: GPL-2.0-or-later
// A HAL file read the way halcmd reads it (LinuxCNC src/hal/utils/halcmd_main.c and
// halcmd.c, checked against LinuxCNC 2.9's halcmd): a line ending in a backslash continues
// on the next line (joined with nothing between), `#` outside quotes starts a comment
// wherever it is, quotes group words and stay part of the word, `name = value` is setp.
// Pure: the caller reads the file.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "error/error.hpp"

namespace i20::linuxcnc {

// Where a statement starts: the file and the 1-based line of its first physical line.
struct SourceLine {
  std::string file;
  int line = 0;
  std::string text() const { return file + ":" + std::to_string(line); }
};

// One halcmd command. `args` are the words after the command with the decorative arrows
// (=>, <=, <=>) of net and link commands removed; quotes are kept, as halcmd keeps them.
struct Statement {
  SourceLine at;
  std::string command;  // "setp" also for `name = value`
  std::vector<std::string> args;
};

// Something halcmd rejects before touching HAL: an unterminated quote, an unknown command,
// a command with too few or too many words. Exit 2 (bad input).
class HalSyntaxError : public UsageError {
 public:
  HalSyntaxError(SourceLine at, const std::string& problem)
      : UsageError(at.text() + ": " + problem), at_(std::move(at)), problem_(problem) {}
  const SourceLine& at() const noexcept { return at_; }
  const std::string& problem() const noexcept { return problem_; }

 private:
  SourceLine at_;
  std::string problem_;
};

// The statements of `text` (the contents of `file`), in order. Throws HalSyntaxError.
std::vector<Statement> read_hal(std::string_view text, const std::string& file);

// `word` without the quotes halcmd keeps: config="a b" -> config=a b.
std::string unquoted(std::string_view word);

}  // namespace i20::linuxcnc
