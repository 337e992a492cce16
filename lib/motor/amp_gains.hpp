// SPDX-License-Identifier: GPL-2.0-or-later
// What the 8I20's current-loop gains (KQP/KQI, KDP/KDI) mean in volts per amp.
//
// The card's PI loop works on normalised quantities (current as a fraction of MAXCURRENT,
// voltage as a fraction of the bus). Mesa does not publish the scaling of the gains, so the
// toolkit assumes the manual's defaults (KQP = KDP = 50, KQI = KDI = 150000, "suitable for a
// large range of motors") are a pole-zero-cancelling PI design for a documented reference
// motor, and scales from there:
//
//   card gain = physical gain * MAXCURRENT / Vbus * (a constant fixed by the reference)
//
// `i20 tune` (lib/profile) designs gains with this scaling; its step response and the
// virtual 8I20 turn card gains back into volts per amp with it. One conversion, so the
// prediction and the simulated card cannot disagree. See docs/motor-model.md.
#pragma once

#include <cstdint>

namespace i20::motor {

// Per-phase (line-to-neutral) winding values; half the line-to-line values of a star motor.
struct WindingParams {
  double resistance_ohm = 0;
  double inductance_h = 0;
};

// The tuning the card's default gains are assumed to be. The reference motor is a generic
// 400 W, 200 V-class AC servo (2.7 A RMS continuous, about 8 A peak, electrical time
// constant L/R = 3 ms) on a 240 V line (340 V bus, the case the manual's brake defaults
// are chosen for), with MAXCURRENT at its peak current as the manual advises, and a
// 500 Hz current-loop bandwidth: well damped with a one-period computation delay at the
// default 12 kHz PWM.
struct ReferenceTuning {
  std::int64_t kp = 50;
  std::int64_t ki = 150000;
  WindingParams motor{2.0, 6.0e-3};
  double max_current_a = 8.0;
  double bus_voltage_v = 340.0;
  double bandwidth_hz = 500.0;
};

// A PI current controller's gains in physical units.
struct PhysicalGains {
  double kp_v_per_a = 0;
  double ki_v_per_as = 0;
};

// Card counts per V/A (proportional) and per V/(A s) (integral) at this MAXCURRENT and bus.
double kp_counts_per_unit(double max_current_a, double bus_voltage_v, const ReferenceTuning& reference);
double ki_counts_per_unit(double max_current_a, double bus_voltage_v, const ReferenceTuning& reference);

// The physical gains of card gains kp/ki at this MAXCURRENT and bus voltage.
PhysicalGains physical_gains(std::int64_t kp, std::int64_t ki, double max_current_a, double bus_voltage_v,
                             const ReferenceTuning& reference = {});

// The manual's default PWM (switching) frequency, 12 kHz (SPECIFICATIONS: "Default is 12 KHz");
// the current loop is taken to run once per PWM period.
inline constexpr double kDefaultPwmHz = 12000.0;

}  // namespace i20::motor
