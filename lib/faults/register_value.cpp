// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/register_value.hpp"

#include <cstdio>
#include <optional>
#include <string>

#include "lbp/bytes.hpp"

namespace i20::faults {
namespace {

constexpr std::uint64_t kLimit = 0xFFFFFFFFFFFFull;  // stop accumulating long before overflow

std::string_view trim(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

int digit_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return 99;
}

// Digits in `base`, '_' allowed between digits. nullopt on anything else.
std::optional<std::uint64_t> digits(std::string_view s, int base) {
  if (s.empty() || s.front() == '_' || s.back() == '_') return std::nullopt;
  std::uint64_t value = 0;
  for (char c : s) {
    if (c == '_') continue;
    const int d = digit_value(c);
    if (d >= base) return std::nullopt;
    value = std::min(value * static_cast<std::uint64_t>(base) + static_cast<std::uint64_t>(d), kLimit);
  }
  return value;
}

std::string quoted(std::string_view s) {
  constexpr std::size_t kShown = 40;
  // Built by appending: GCC 12's -O3 -Wrestrict misfires on `"'" + std::string(...)`.
  std::string out = "'";
  out += s.substr(0, kShown);
  out += s.size() > kShown ? "...'" : "'";
  return out;
}

[[noreturn]] void reject(std::string_view what, const std::string& why) {
  throw BadRegisterValue(std::string(what) + ": " + why);
}

std::uint16_t fit(std::uint64_t value, std::string_view text, std::string_view what) {
  if (value <= 0xFFFF) return static_cast<std::uint16_t>(value);
  std::string why = quoted(text) + " does not fit the 16-bit register (at most 0xFFFF = 65535)";
  // A 32-bit paste is most likely SSLBP's Interface1 word: FAULT high, STATUS low.
  if (value <= 0xFFFFFFFF)
    why += "; if it is SSLBP's Interface1 word, FAULT is " + lbp::hex_value(value >> 16, 4) + " and STATUS " +
           lbp::hex_value(value & 0xFFFF, 4);
  reject(what, why);
}

constexpr const char* kHowTo = "write hex as 0x0102 or 0102h, binary as 0b100000010, decimal as 258";

}  // namespace

std::uint16_t parse_register_value(std::string_view text, std::string_view what) {
  const auto s = trim(text);
  if (s.empty()) reject(what, std::string("no value given; ") + kHowTo);
  if (s.front() == '-') reject(what, quoted(s) + " is negative; the register is an unsigned 16-bit value");
  const auto prefix = s.substr(0, 2);
  std::optional<std::uint64_t> value;
  if (s.size() > 1 && (s.back() == 'h' || s.back() == 'H')) {
    value = digits(s.substr(0, s.size() - 1), 16);
  } else if (prefix == "0x" || prefix == "0X") {
    value = digits(s.substr(2), 16);
  } else if (prefix == "0b" || prefix == "0B") {
    value = digits(s.substr(2), 2);
  } else {
    value = digits(s, 10);
    // "0102" reads differently as hex and decimal once it is 10 or more.
    if (value && s.front() == '0' && *value >= 10)
      reject(what, quoted(s) + " is ambiguous (hex without its prefix?); write 0x" + std::string(s) +
                       " for hex or drop the leading zero for decimal");
    if (!value && digits(s, 16))
      reject(what, quoted(s) + " looks like hex without a prefix; write 0x" + std::string(s) + " or " +
                       std::string(s) + "h");
  }
  if (!value) reject(what, quoted(s) + " is not a number; " + kHowTo);
  return fit(*value, s, what);
}

}  // namespace i20::faults
