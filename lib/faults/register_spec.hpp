// SPDX-License-Identifier: GPL-2.0-or-later
// A FAULT or STATUS value as a LinuxCNC user may have it: a number, or the bits that are set,
// by name ("fault.no-enable,fault.bus-underv" from halshow, "no-enable+BUSLOVFAULT", a full
// pin "hm2_7i96s.0.8i20.0.0.status.pid-on").
#pragma once

#include <cstdint>
#include <string_view>

#include "faults/bit_info.hpp"
#include "faults/fault_table.hpp"

namespace i20::faults {

// A number is read by parse_register_value; anything else as bit names (slugs, manual names
// or LinuxCNC pins) joined by ',' or '+', giving the value with exactly those bits set.
// Throws BadRegisterValue or UnknownBit (a STATUS pin given for FAULT is refused, named).
std::uint16_t parse_register_spec(std::string_view text, Register reg,
                                  const FaultTable& table = FaultTable::builtin());

}  // namespace i20::faults
