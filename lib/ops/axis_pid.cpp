// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/axis_pid.hpp"

#include <cmath>
#include <numbers>

#include "error/error.hpp"
#include "motor/motor.hpp"

namespace i20::ops {
namespace {

void require(bool ok, const std::string& why) {
  if (!ok) throw UsageError(why);
}

bool positive(double v) {
  return v > 0 && std::isfinite(v);
}

void check(const AxisPidRequest& r) {
  const auto& a = r.axis;
  require(positive(a.inertia_kgm2), "the inertia must be positive");
  require(positive(a.torque_constant_nm_per_a), "the torque constant must be positive");
  require(positive(a.units_per_rad), "the lead (machine units per motor turn) must be positive");
  require(positive(a.max_current_a), "the maximum current must be positive");
  require(a.viscous_nm_per_rad_s >= 0 && std::isfinite(a.viscous_nm_per_rad_s),
          "the viscous friction must not be negative");
  require(a.coulomb_nm >= 0 && std::isfinite(a.coulomb_nm), "the Coulomb friction must not be negative");
  require(std::isfinite(a.bias_nm), "the bias must be a finite torque");
  require(!a.resonance_hz || positive(*a.resonance_hz), "the resonance must be a positive frequency");
  require(a.rotor_inertia_kgm2 >= 0 && a.rotor_inertia_kgm2 < a.inertia_kgm2,
          "the rotor's inertia must be below the total inertia (the rest is the load's)");
  require(a.coupling_damping_ratio > 0 && a.coupling_damping_ratio <= 1,
          "the damping ratio must be above 0, at most 1");
  require(positive(r.timing.servo_period_s), "the servo period must be positive");
  require(r.timing.delay_s >= 0 && r.timing.delay_s <= r.timing.servo_period_s,
          "the delay must be from 0 to the servo period (the command is written within the period)");
  require(r.margins.phase_deg >= 30 && r.margins.phase_deg <= 80,
          "the phase margin must be 30 to 80 degrees");
  require(r.margins.gain_db >= 3 && r.margins.gain_db <= 20, "the gain margin must be 3 to 20 dB");
  require(r.joint >= 0 && r.joint <= 15, "the joint must be 0 to 15");
  require(r.notch == mechanics::NotchUse::Never || (a.resonance_hz && a.rotor_inertia_kgm2 > 0),
          "a notch needs the resonance and the rotor's inertia (a two-mass model): give --resonance and "
          "--rotor-inertia, or a motor file with a machine stiffness");
  if (r.notch != mechanics::NotchUse::Never)
    require(*a.resonance_hz * (1 + mechanics::kNotchResonanceSpread) < 0.5 / r.timing.servo_period_s,
            "a notch at the resonance needs it (and 10% above) below half the servo rate");
  if (r.move) {
    require(r.truth.has_value(), "a simulated move needs the motor's model (a motor file)");
    require(r.move->distance != 0 && std::isfinite(r.move->distance), "the move's distance must not be 0");
    require(positive(r.move->speed) && positive(r.move->accel),
            "the move's speed and acceleration must be positive");
    require(r.move->duration_s() <= 60, "the simulated move must take at most 60 s");
  }
}

}  // namespace

AxisPidResult design_axis_pid(const AxisPidRequest& request) {
  check(request);
  AxisPidResult result;
  result.gains = mechanics::design_pid(request.axis, request.timing, request.margins, request.notch);
  result.ini = mechanics::ini_section(request.joint, result.gains);
  if (request.move) {
    auto running = *request.truth;
    running.brake_engaged = false;  // a machine moves with its holding brake released
    result.trace = mechanics::simulate_move(running, result.gains, request.axis.units_per_rad, *request.move,
                                            request.timing);
  }
  return result;
}

mechanics::AxisModel axis_from_motor(const motor::MotorParams& m, double units_per_metre,
                                     double max_current_a) {
  require(m.machine.lead_m_per_turn > 0,
          "the motor file gives no machine.lead: the gains need the machine units per motor turn");
  return mechanics::axis_model_of(m, m.machine.lead_m_per_turn * units_per_metre / (2 * std::numbers::pi),
                                  max_current_a);
}

}  // namespace i20::ops
