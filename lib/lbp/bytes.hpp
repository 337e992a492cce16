// SPDX-License-Identifier: GPL-2.0-or-later
// Byte containers and little-endian helpers shared by every layer.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace i20::lbp {

using Byte = std::uint8_t;
using Bytes = std::vector<Byte>;
using ByteView = std::span<const Byte>;

// LBP multi-byte data are little endian: the byte at the lower address is the LSB.
inline std::uint64_t read_le(ByteView bytes) {
  std::uint64_t value = 0;
  for (std::size_t i = bytes.size(); i-- > 0;) value = (value << 8) | bytes[i];
  return value;
}

// A 32-bit register (hostmot2's and SSLBP's words over LBP16) from its little-endian bytes.
inline std::uint32_t read_le32(ByteView bytes) {
  return static_cast<std::uint32_t>(read_le(bytes));
}

// `count` bytes of `value`, least significant first; past 8 bytes, zeros (the value
// zero-extended: shifting a 64-bit value by 64 or more is undefined).
inline void append_le(Bytes& out, std::uint64_t value, std::size_t count) {
  for (std::size_t i = 0; i < count; ++i)
    out.push_back(i < 8 ? static_cast<Byte>(value >> (8 * i)) : Byte{0});
}

inline Bytes to_le(std::uint64_t value, std::size_t count) {
  Bytes out;
  append_le(out, value, count);
  return out;
}

// "6e 10 00 aa": for error messages, logs and tests.
std::string to_hex(ByteView bytes);

// "0x8CA0": the low `digits` hexadecimal digits of `value`, upper case, zero-padded. The
// one way the toolkit shows register values, addresses and command words.
std::string hex_value(std::uint64_t value, int digits);

// Parses "6e1000aa", "6e 10 00 aa" or "6E:10"; throws std::invalid_argument on bad input.
Bytes from_hex(const std::string& text);

}  // namespace i20::lbp
