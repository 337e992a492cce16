// SPDX-License-Identifier: GPL-2.0-or-later
// Small text helpers the loaders and parsers share (names are case-insensitive,
// values arrive with stray spaces).
#pragma once

#include <cctype>
#include <optional>
#include <string>
#include <string_view>

namespace i20::params {

inline std::string trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return std::string(s);
}

inline bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i])))
      return false;
  return true;
}

inline std::string lower(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

inline std::string upper(std::string_view s) {
  std::string out(s);
  for (auto& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// The first control character of `s` (C0, DEL), if any; `allow_lines` lets '\n' and '\t' pass.
inline std::optional<char> control_character(std::string_view s, bool allow_lines = false) {
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if ((u < 0x20 || u == 0x7F) && !(allow_lines && (c == '\n' || c == '\t'))) return c;
  }
  return std::nullopt;
}

// "\x1B": how a control character is shown.
inline std::string escaped(char c) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  const auto u = static_cast<unsigned char>(c);
  return std::string("\\x") + kDigits[u >> 4] + kDigits[u & 0xF];
}

// Text from a user or a file made safe to print: control characters (ESC, BEL, CR, ...) and
// DEL become \xNN, so a name or a typed value cannot move the cursor or clear the screen.
// Line breaks stay (messages are lines); UTF-8 passes unchanged.
inline std::string printable(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (const char c : s)
    out += control_character(std::string_view(&c, 1), true) ? escaped(c) : std::string(1, c);
  return out;
}

}  // namespace i20::params
