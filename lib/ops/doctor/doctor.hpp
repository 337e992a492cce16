// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 doctor`'s matcher: LinuxCNC's log lines (halrun's terminal output, linuxcnc.log,
// dmesg, `halcmd show pin`) to findings, each with what LinuxCNC said (the lines, by file
// and line number), the cause, the evidence, the fix and the section of
// docs/field-messages.md it rests on. The messages and their explanations are data
// (params/linuxcnc-messages.yaml, compiled in). Pure: no I/O; the caller reads the files.
#pragma once

#include <cstddef>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

namespace i20::doctor {

// A message book that cannot be read (bad YAML, a bad regular expression, a missing key).
struct BookError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

enum class Severity { Error, Warning, Note };
const char* to_string(Severity s);

struct Rule {
  std::string id;
  bool known = false;  // a normal line: recognised, counted, never a finding
  Severity severity = Severity::Error;
  std::string title, pattern, evidence, cause, said_by, docs;
  std::vector<std::string> fix;
  std::regex re;
};

class MessageBook {
 public:
  // params/linuxcnc-messages.yaml as compiled in.
  static const MessageBook& builtin();
  // `origin` names the text in errors (a file name).
  static MessageBook load_string(const std::string& yaml, const std::string& origin);

  const std::vector<Rule>& rules() const { return rules_; }
  // The first rule whose pattern is found in `line`, or nullptr.
  const Rule* match(const std::string& line, std::smatch& groups) const;
  // Whether an unmatched line is about the card (hm2, sserial, 8I20): reported as not recognised.
  bool watched(const std::string& line) const;

 private:
  std::vector<Rule> rules_;
  std::regex watch_;
};

struct LogLine {
  std::string file;  // as the user named it; "-" for standard input
  std::size_t number = 0;
  std::string text;
};

// Where a message was said: the first few lines kept verbatim, all counted.
struct Said {
  std::string file;
  std::size_t line = 0;
  std::string text;
};

struct Finding {
  std::string id;
  Severity severity = Severity::Error;
  std::string title, evidence, cause, said_by, docs;
  std::vector<std::string> fix;
  std::vector<Said> said;  // up to kKeptLines, in order
  std::size_t count = 0;   // every line that gave this very evidence
  std::size_t last_line = 0;
  std::string last_file;
};

struct Unrecognised {
  Said first;
  std::size_t count = 0;
};

struct Diagnosis {
  std::vector<Finding> findings;  // in the order of their first line
  std::vector<Unrecognised> unrecognised;
  std::size_t lines = 0;  // read
  std::size_t known = 0;  // normal lines recognised

  // Error or warning findings (notes do not count).
  std::size_t problems() const;
};

inline constexpr std::size_t kKeptLines = 3;

// Lines that give the same rule and the same evidence are one finding with a count.
Diagnosis diagnose(const std::vector<LogLine>& lines, const MessageBook& book = MessageBook::builtin());

// Splits a text into numbered lines (a trailing '\r' dropped), for diagnose().
std::vector<LogLine> split_lines(const std::string& text, const std::string& file);

}  // namespace i20::doctor
