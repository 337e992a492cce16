// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/fault_mask.hpp"

#include <string>

namespace i20::faults {
namespace {

std::string describe(const BitInfo& b) {
  return b.slug + " (" + std::string(to_string(b.reg)) + " bit " + std::to_string(b.bit) + ", " + b.name +
         ")";
}

// "bus-under-voltage (FAULT bit 8, BUSLOVFAULT)", joined with "and".
std::string maskable_list(const FaultTable& table) {
  std::string out;
  const auto& bits = table.bits(Register::Fault);
  std::size_t count = 0;
  for (const auto& b : bits)
    if (b.maskable) out += std::string(count++ ? " and " : "") + describe(b);
  return count ? out : "none";
}

unsigned checked(unsigned bit) {
  if (bit > 15) throw UsageError("FAULTMASK bit " + std::to_string(bit) + " does not exist (bits 0..15)");
  return bit;
}

}  // namespace

const BitInfo& maskable_fault(std::string_view key, const FaultTable& table) {
  if (const BitInfo* status = table.find(key); status && status->reg == Register::Status)
    throw NotMaskable(describe(*status) + " is a STATUS bit; FAULTMASK masks FAULT bits only, and only " +
                      maskable_list(table) + " is maskable");
  const BitInfo& b = table.get(Register::Fault, key);
  if (!b.maskable)
    throw NotMaskable(describe(b) + " cannot be masked; only " + maskable_list(table) + " is maskable");
  return b;
}

std::uint16_t set_fault_masked(std::uint16_t faultmask, std::string_view key, bool masked,
                               const FaultTable& table) {
  const BitInfo& b = maskable_fault(key, table);
  return masked ? mask_bit(faultmask, b.bit) : unmask_bit(faultmask, b.bit);
}

std::uint16_t mask_bit(std::uint16_t faultmask, unsigned bit) {
  return static_cast<std::uint16_t>(faultmask & ~(1u << checked(bit)));
}

std::uint16_t unmask_bit(std::uint16_t faultmask, unsigned bit) {
  return static_cast<std::uint16_t>(faultmask | (1u << checked(bit)));
}

MaskState mask_state(std::uint16_t fault, std::uint16_t faultmask, const FaultTable& table) {
  const std::uint16_t maskable = table.maskable_bits();
  const auto cleared = static_cast<std::uint16_t>(~faultmask);
  MaskState s;
  s.fault = fault;
  s.faultmask = faultmask;
  s.masked = static_cast<std::uint16_t>(fault & cleared & maskable);
  s.unmasked = static_cast<std::uint16_t>(fault & ~s.masked);
  s.ineffective = static_cast<std::uint16_t>(cleared & ~maskable);
  return s;
}

}  // namespace i20::faults
