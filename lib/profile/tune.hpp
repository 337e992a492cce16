// SPDX-License-Identifier: GPL-2.0-or-later
// Current-loop tuning calculator: card gains for a motor, scaled from a reference tuning.
//
// The 8I20's PI current loop works on normalised quantities: current as a fraction of
// MAXCURRENT, voltage as a fraction of the bus voltage. Mesa does not publish the internal
// scaling of KQP/KQI, so this calculator cannot compute absolute gains. It assumes the
// manual's defaults (KQP = KDP = 50, KQI = KDI = 150000, "suitable for a large range of
// motors") are a good tuning for a documented reference motor, and scales them with the
// standard PI design for an R-L load (pole-zero cancellation):
//
//   Kp [V/A] = L * wc          Ki [V/(A s)] = R * wc          wc = 2 pi * bandwidth
//   card gain = physical gain * MAXCURRENT / Vbus * (a constant fixed by the reference)
//
// so Kp scales with L, Ki with R, both with bandwidth and MAXCURRENT, both inversely with
// the bus voltage. The result is a starting point relative to the reference, to be
// checked on the machine. See profiles/TUNING.md.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "motor/amp_gains.hpp"
#include "params/param_db.hpp"
#include "profile/finding.hpp"

namespace i20::profile {

// Per-phase (line-to-neutral) values; half the line-to-line values of a star motor.
using MotorModel = motor::WindingParams;

// The tuning the card's default gains are assumed to be (lib/motor/amp_gains.hpp: the
// scaling is shared with the motor model, so the virtual 8I20 reads gains the same way).
using ReferenceTuning = motor::ReferenceTuning;

// With a one-period delay, the loop z^2 - z + wc*T = 0 is critically damped at wc*T = 0.25
// and overshoots about 5% at 0.35 (~670 Hz at 12 kHz); beyond that it rings.
inline constexpr double kMaxDampedWcT = 0.35;

struct TuneRequest {
  MotorModel motor;
  double max_current_a = 0;  // the MAXCURRENT the gains are for
  double bus_voltage_v = 0;  // nominal DC bus
  double bandwidth_hz = ReferenceTuning{}.bandwidth_hz;
  double sample_rate_hz = 12000;  // the loop rate assumed (default PWM frequency, manual SPECIFICATIONS)
  ReferenceTuning reference;
};

// What card gains mean in volts per amp for one MAXCURRENT and bus voltage, per the model.
using PhysicalGains = motor::PhysicalGains;

struct TuneResult {
  std::int64_t kp = 0;  // for KQP and KDP
  std::int64_t ki = 0;  // for KQI and KDI
  double kp_exact = 0;  // before rounding and clamping
  double ki_exact = 0;
  PhysicalGains target;           // L*wc and R*wc
  PhysicalGains achieved;         // what the rounded, clamped card gains give
  std::vector<Finding> warnings;  // clamped, coarse resolution, bandwidth near the loop rate
};

// Throws TuneError for values that make no sense (non-positive R, L, bus, bandwidth, or a
// MAXCURRENT outside 0..30 A). Gains are clamped to the database ranges of NVKQP and NVKQI
// (and kept at least 1: a zero gain switches the term off) with a warning.
TuneResult tune(const TuneRequest& request, const params::ParamDb& db);

// The physical gains of card gains kp/ki at this MAXCURRENT and bus voltage, per the model.
using motor::physical_gains;

}  // namespace i20::profile
