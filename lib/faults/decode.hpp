// SPDX-License-Identifier: GPL-2.0-or-later
// Decoding a FAULT or STATUS reading into the bits that are set.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "faults/fault_table.hpp"

namespace i20::faults {

struct DecodedBit {
  Register reg = Register::Fault;
  unsigned bit = 0;
  // A copy, so a decoded reading outlives the table it came from. Empty: the manual
  // defines no such bit.
  std::optional<BitInfo> info;

  bool reserved() const { return !info; }
  // The manual's name, or "reserved bit N".
  std::string label() const;
  // "reserved/undocumented bit N set" for a reserved bit, else the entry's meaning.
  std::string meaning() const;
};

struct Decoded {
  Register reg = Register::Fault;
  std::uint16_t value = 0;
  std::vector<DecodedBit> bits;  // the set bits, lowest first
  std::uint16_t reserved = 0;    // set bits the manual does not define

  bool empty() const { return bits.empty(); }
};

// The bit of `reg` as `table` describes it (reserved if it does not).
DecodedBit decode_bit(Register reg, unsigned bit, const FaultTable& table = FaultTable::builtin());
Decoded decode(Register reg, std::uint16_t value, const FaultTable& table = FaultTable::builtin());
Decoded decode_fault(std::uint16_t fault, const FaultTable& table = FaultTable::builtin());
Decoded decode_status(std::uint16_t status, const FaultTable& table = FaultTable::builtin());

}  // namespace i20::faults
