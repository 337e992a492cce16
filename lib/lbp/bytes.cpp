// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp/bytes.hpp"

#include <cctype>
#include <stdexcept>

namespace i20::lbp {

std::string to_hex(ByteView bytes) {
  static constexpr char digits[] = "0123456789abcdef";
  std::string text;
  text.reserve(bytes.size() * 3);
  for (Byte b : bytes) {
    if (!text.empty()) text.push_back(' ');
    text.push_back(digits[b >> 4]);
    text.push_back(digits[b & 0x0F]);
  }
  return text;
}

std::string hex_value(std::uint64_t value, int digits) {
  static constexpr char upper_digits[] = "0123456789ABCDEF";
  std::string text = "0x";
  for (int i = digits - 1; i >= 0; --i) text.push_back(upper_digits[(value >> (4 * i)) & 0xF]);
  return text;
}

Bytes from_hex(const std::string& text) {
  Bytes out;
  int pending = -1;
  for (char c : text) {
    if (c == ' ' || c == ':' || c == '\t') continue;
    if (!std::isxdigit(static_cast<unsigned char>(c)))
      throw std::invalid_argument("not a hexadecimal digit: '" + std::string(1, c) + "'");
    const int nibble = std::isdigit(static_cast<unsigned char>(c))
                           ? c - '0'
                           : std::tolower(static_cast<unsigned char>(c)) - 'a' + 10;
    if (pending < 0) {
      pending = nibble;
    } else {
      out.push_back(static_cast<Byte>((pending << 4) | nibble));
      pending = -1;
    }
  }
  if (pending >= 0) throw std::invalid_argument("odd number of hexadecimal digits in '" + text + "'");
  return out;
}

}  // namespace i20::lbp
