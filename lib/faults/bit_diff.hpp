// SPDX-License-Identifier: GPL-2.0-or-later
// What changed between two readings of FAULT or STATUS, for `watch`-style monitoring:
// a fault that rose is news, one that fell was cleared (or, for a live STATUS bit, went
// away by itself).
#pragma once

#include <cstdint>
#include <vector>

#include "faults/decode.hpp"

namespace i20::faults {

struct BitChanges {
  Register reg = Register::Fault;
  std::uint16_t before = 0;
  std::uint16_t after = 0;
  std::vector<DecodedBit> rose;  // 0 -> 1, lowest bit first
  std::vector<DecodedBit> fell;  // 1 -> 0, lowest bit first

  bool empty() const { return before == after; }
  std::uint16_t rose_bits() const { return static_cast<std::uint16_t>(after & ~before); }
  std::uint16_t fell_bits() const { return static_cast<std::uint16_t>(before & ~after); }
};

BitChanges diff(Register reg, std::uint16_t before, std::uint16_t after,
                const FaultTable& table = FaultTable::builtin());

}  // namespace i20::faults
