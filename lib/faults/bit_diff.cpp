// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/bit_diff.hpp"

namespace i20::faults {

BitChanges diff(Register reg, std::uint16_t before, std::uint16_t after, const FaultTable& table) {
  BitChanges out{reg, before, after, {}, {}};
  for (unsigned bit = 0; bit < 16; ++bit) {
    // Two plain ifs on purpose: GCC 12 -O2 miscompiles `(cond ? out.rose : out.fell)
    // .push_back(...)` into an NRVO result here (both lists came back empty).
    const unsigned mask = 1u << bit;
    if (out.rose_bits() & mask) out.rose.push_back(decode_bit(reg, bit, table));
    if (out.fell_bits() & mask) out.fell.push_back(decode_bit(reg, bit, table));
  }
  return out;
}

}  // namespace i20::faults
