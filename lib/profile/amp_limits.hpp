// SPDX-License-Identifier: GPL-2.0-or-later
// The 8I20's own limits that profiles and tuning are judged against, whatever range a
// parameter database overlay gives: an overlay can place a parameter, not make the
// hardware stronger. Each limit has one home.
#pragma once

#include <string>

namespace i20::profile {

// Manual, MAXCURRENT ("or to 30A if the motor has a higher than 30 A RMS current rating")
// and SPECIFICATIONS (MAX MOTOR CURRENT 25C CASE: 30 A RMS).
inline constexpr double kAmpMaxCurrentA = 30.0;

// Manual, FAULT CONDITIONS (MAXBUSVFAULT: high motor voltage fault, fixed at 400 V) and
// MOTOR POWER (35 to 400 VDC). A property of a FAULT bit, so it lives in the fault table
// (params/faults.yaml, the live check of max-bus-voltage), which the diagnosis of that
// fault reads too.
double amp_max_bus_v();

// "30 A", "400 V": a limit as the messages quote it.
std::string limit_text(double value, const char* unit);

}  // namespace i20::profile
