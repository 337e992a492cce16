// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/decode.hpp"

namespace i20::faults {

std::string DecodedBit::label() const {
  return info ? info->name : "reserved bit " + std::to_string(bit);
}

std::string DecodedBit::meaning() const {
  return info ? info->meaning : "reserved/undocumented bit " + std::to_string(bit) + " set";
}

DecodedBit decode_bit(Register reg, unsigned bit, const FaultTable& table) {
  DecodedBit out{reg, bit, std::nullopt};
  if (const BitInfo* b = table.find(reg, bit)) out.info = *b;
  return out;
}

Decoded decode(Register reg, std::uint16_t value, const FaultTable& table) {
  Decoded out{reg, value, {}, 0};
  for (unsigned bit = 0; bit < 16; ++bit) {
    if (!(value & (1u << bit))) continue;
    out.bits.push_back(decode_bit(reg, bit, table));
    if (out.bits.back().reserved()) out.reserved |= static_cast<std::uint16_t>(1u << bit);
  }
  return out;
}

Decoded decode_fault(std::uint16_t fault, const FaultTable& table) {
  return decode(Register::Fault, fault, table);
}

Decoded decode_status(std::uint16_t status, const FaultTable& table) {
  return decode(Register::Status, status, table);
}

}  // namespace i20::faults
