// SPDX-License-Identifier: GPL-2.0-or-later
// Physical quantities in profile metadata and `i20 tune`'s options ("2.7 A", "6.2 mH",
// "1.9 ohm", "170 V", "500 Hz").
//
// Parameter values go through params::parse_value (the database knows their scale); these
// are the motor, supply and tuning facts that have no card parameter behind them. Both read
// units from the one table in params/value.hpp, by the same rule: SI spelling, exact case.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace i20::profile {

enum class Quantity { Current, Resistance, Inductance, Voltage, Frequency };

// The value in SI units (A, ohm, H, V, Hz), or nullopt with `why` set ("7.5a: unit 'a' is
// not known; did you mean 'A'?"). The unit is required: a bare "6.2" could be H or mH.
// Accepted, in exact case: A, mA; ohm, mohm (also "ohms" and the Greek sign); H, mH, uH
// (also the micro sign); V, mV; Hz, kHz. The number is written like a parameter value (one
// sign, a decimal point, an optional exponent; no NaN or infinity); the value must be
// positive and within 1e-9 .. 1e9 of the base unit.
std::optional<double> parse_quantity(Quantity kind, std::string_view text, std::string& why);

// Formatting that parse_quantity reads back: "2.7 A", "6.2 mH", "1.9 ohm", "170 V", "500 Hz".
std::string format_quantity(Quantity kind, double si_value);

}  // namespace i20::profile
