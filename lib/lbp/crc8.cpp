// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp/crc8.hpp"

#include <array>

namespace i20::lbp {
namespace {

// 0x8C is the polynomial 0x31 bit-reversed, because the CRC shifts right (LSB first).
constexpr std::array<Byte, 256> make_table() {
  std::array<Byte, 256> table{};
  for (unsigned i = 0; i < 256; ++i) {
    unsigned crc = i;
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1U) ? (crc >> 1) ^ 0x8CU : crc >> 1;
    table[i] = static_cast<Byte>(crc);
  }
  return table;
}

constexpr auto kTable = make_table();

}  // namespace

void Crc8::update(Byte byte) {
  value_ = kTable[value_ ^ byte];
}

Byte crc8(ByteView bytes) {
  Crc8 crc;
  crc.update(bytes);
  return crc.value();
}

}  // namespace i20::lbp
