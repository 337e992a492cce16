// SPDX-License-Identifier: GPL-2.0-or-later
// Turns what a user pastes (from RPD, halshow, a log) into a 16-bit register value.
//
// Accepted: hex "0x0102" or "0102h", binary "0b100000010" ('_' may group digits), and
// decimal "258". Refused with a message saying how to write it: garbage, negative
// numbers, values above 0xFFFF, and decimal numbers with a leading zero ("0102"), which
// are too easily a hex value with its prefix lost — decoding it as decimal would point
// at the wrong faults.
#pragma once

#include <cstdint>
#include <string_view>

#include "faults/error.hpp"

namespace i20::faults {

// `what` names the value in messages ("FAULT", "STATUS", "FAULTMASK").
// Throws BadRegisterValue.
std::uint16_t parse_register_value(std::string_view text, std::string_view what = "the value");

}  // namespace i20::faults
