// SPDX-License-Identifier: GPL-2.0-or-later
// FAULTMASK: which FAULT bits are kept off the fault output (TB1 pins 5 and 6).
//
// A 0 bit masks (manual, FAULT MASK), so "nothing masked" is 0xFFFF and masking bus
// under-voltage (bit 8) gives 0xFEFF. Only bits the table marks maskable can be masked
// (the manual: only BUSLOVFAULT); changing the mask keeps every other bit as it was read,
// so a tool never silently rewrites bits it was not asked about.
#pragma once

#include <cstdint>
#include <string_view>

#include "faults/fault_table.hpp"

namespace i20::faults {

inline constexpr std::uint16_t kNothingMasked = 0xFFFF;

// The maskable FAULT bit named by `key` (slug, name, LinuxCNC pin or bit number).
// Throws UnknownBit, or NotMaskable naming the bits that are maskable.
const BitInfo& maskable_fault(std::string_view key, const FaultTable& table = FaultTable::builtin());

// `faultmask` as read, with the bit named by `key` masked (0) or unmasked (1).
// Refuses non-maskable bits like maskable_fault().
std::uint16_t set_fault_masked(std::uint16_t faultmask, std::string_view key, bool masked,
                               const FaultTable& table = FaultTable::builtin());

// Arithmetic only (bit 0..15, else UsageError); prefer set_fault_masked().
std::uint16_t mask_bit(std::uint16_t faultmask, unsigned bit);
std::uint16_t unmask_bit(std::uint16_t faultmask, unsigned bit);

// What a FAULT reading means for the fault output under a given FAULTMASK.
struct MaskState {
  std::uint16_t fault = 0;
  std::uint16_t faultmask = kNothingMasked;
  std::uint16_t masked = 0;    // set faults kept off the fault output
  std::uint16_t unmasked = 0;  // set faults that switch the fault output off and stop the drive
  // 0 bits of FAULTMASK where no maskable fault is: the manual gives them no effect.
  std::uint16_t ineffective = 0;

  // The fault output is on (closed) in normal operation and off on a non-masked fault.
  bool fault_output_on() const { return unmasked == 0; }
};

MaskState mask_state(std::uint16_t fault, std::uint16_t faultmask,
                     const FaultTable& table = FaultTable::builtin());

}  // namespace i20::faults
