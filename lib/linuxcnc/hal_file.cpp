// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_file.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <optional>

namespace i20::linuxcnc {
namespace {

// A logical line: physical lines joined at trailing backslashes.
struct LogicalLine {
  int first_line = 0;
  std::string text;
};

std::vector<LogicalLine> join_continuations(std::string_view text) {
  std::vector<LogicalLine> lines;
  int number = 0;
  bool continuing = false;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const auto end = text.find('\n', pos);
    std::string_view physical =
        text.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
    pos = end == std::string_view::npos ? text.size() : end + 1;
    ++number;
    if (!physical.empty() && physical.back() == '\r')
      physical.remove_suffix(1);  // halcmd warns, then reads on
    if (!continuing) lines.push_back({number, {}});
    // halcmd joins only when the backslash is the very last character: "\ " does not continue.
    continuing = !physical.empty() && physical.back() == '\\';
    if (continuing) physical.remove_suffix(1);
    lines.back().text += physical;
  }
  return lines;
}

enum class Quote { None, Single, Double };

// Splits at whitespace outside quotes and stops at `#` outside quotes. nullopt: a quote
// is still open at the end of the line.
std::optional<std::vector<std::string>> split_words(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  Quote quote = Quote::None;
  for (char c : line) {
    if (quote != Quote::None) {
      word += c;
      if ((quote == Quote::Single && c == '\'') || (quote == Quote::Double && c == '"')) quote = Quote::None;
      continue;
    }
    if (c == '#') break;
    if (std::isspace(static_cast<unsigned char>(c))) {
      if (in_word) words.push_back(std::move(word));
      word.clear();
      in_word = false;
      continue;
    }
    in_word = true;
    word += c;
    if (c == '\'') quote = Quote::Single;
    if (c == '"') quote = Quote::Double;
  }
  if (quote != Quote::None) return std::nullopt;
  if (in_word) words.push_back(std::move(word));
  return words;
}

// halcmd's commands (LinuxCNC 2.9 `help`, plus the test-suite one) and how many words each
// takes after the command: at least `min`, at most `max` (-1: any number).
struct CommandShape {
  std::string_view name;
  int min;
  int max;
};
constexpr std::array<CommandShape, 40> kCommands{{
    {"addf", 2, 3},      {"alias", 3, 3},   {"debug", 1, 1},   {"delf", 1, 2},
    {"delsig", 1, 1},    {"echo", 0, 0},    {"exit", 0, -1},   {"getp", 1, 1},
    {"gets", 1, 1},      {"help", 0, 1},    {"linkpp", 2, 2},  {"linkps", 2, 2},
    {"linksp", 2, 2},    {"list", 1, -1},   {"loadrt", 1, -1}, {"loadusr", 1, -1},
    {"lock", 0, 1},      {"net", 2, -1},    {"newsig", 2, 2},  {"print", 0, -1},
    {"ptype", 1, 1},     {"quit", 0, -1},   {"save", 0, 2},    {"setp", 2, 2},
    {"sets", 2, 2},      {"show", 0, -1},   {"source", 1, 1},  {"start", 0, 0},
    {"status", 0, 1},    {"stop", 0, 0},    {"stype", 1, 1},   {"unalias", 2, 2},
    {"unecho", 0, 0},    {"unlinkp", 1, 1}, {"unload", 1, 1},  {"unloadrt", 1, 1},
    {"unloadusr", 1, 1}, {"unlock", 0, 1},  {"waitusr", 1, 1}, {"setexact_for_test_suite_only", 0, 0},
}};

const CommandShape* command_shape(std::string_view name) {
  const auto* it =
      std::find_if(kCommands.begin(), kCommands.end(), [&](const auto& c) { return c.name == name; });
  return it == kCommands.end() ? nullptr : it;
}

bool is_arrow(std::string_view word) {
  return word == "=>" || word == "<=" || word == "<=>";
}

bool takes_arrows(std::string_view command) {
  return command == "net" || command == "linkpp" || command == "linkps" || command == "linksp";
}

std::string count_words(int n) {
  return std::to_string(n) + (n == 1 ? " word" : " words");
}

Statement statement_of(std::vector<std::string> words, SourceLine at) {
  Statement s{std::move(at), {}, {}};
  if (words.size() == 3 && words[1] == "=") {  // halcmd's shorthand for setp
    s.command = "setp";
    s.args = {words[0], words[2]};
    return s;
  }
  s.command = words.front();
  const auto* shape = command_shape(s.command);
  if (shape == nullptr) throw HalSyntaxError(s.at, "unknown command '" + s.command + "'");
  for (std::size_t i = 1; i < words.size(); ++i)
    if (!(takes_arrows(s.command) && is_arrow(words[i]))) s.args.push_back(std::move(words[i]));
  const int n = static_cast<int>(s.args.size());
  if (n < shape->min) {
    const std::string need =
        s.command == "net" ? "a signal name and at least one pin" : count_words(shape->min);
    throw HalSyntaxError(s.at, s.command + " needs " + need + ", " + count_words(n) + " given");
  }
  if (shape->max >= 0 && n > shape->max)
    throw HalSyntaxError(
        s.at, s.command + " takes at most " + count_words(shape->max) + ", " + count_words(n) + " given");
  return s;
}

}  // namespace

std::vector<Statement> read_hal(std::string_view text, const std::string& file) {
  std::vector<Statement> statements;
  for (auto& line : join_continuations(text)) {
    SourceLine at{file, line.first_line};
    auto words = split_words(line.text);
    if (!words) throw HalSyntaxError(at, "unterminated quoted string");
    if (words->empty()) continue;
    statements.push_back(statement_of(std::move(*words), std::move(at)));
  }
  return statements;
}

std::string unquoted(std::string_view word) {
  std::string out;
  for (char c : word)
    if (c != '"' && c != '\'') out += c;
  return out;
}

}  // namespace i20::linuxcnc
