// SPDX-License-Identifier: GPL-2.0-or-later
#include "motor/motor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "motor/error.hpp"

namespace i20::motor {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double wrap(double angle) {
  const double a = std::fmod(angle, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

double square(Dq v) {
  return v.d * v.d + v.q * v.q;
}

void require(bool ok, const std::string& what) {
  if (!ok) throw MotorError(what);
}

// Rotor motion over t under a constant net torque (friction's sign fixed) and viscous
// friction B: w(t) = w_ss + (w0 - w_ss) exp(-B t / J).
struct Motion {
  double speed = 0;    // at t
  double angle = 0;    // travelled by t
  double viscous = 0;  // B * integral of w^2
};

Motion coast(double w0, double net, double inertia, double viscous, double t) {
  if (viscous <= 0) {
    const double w = w0 + net * t / inertia;
    return {w, w0 * t + net * t * t / (2 * inertia), 0};
  }
  const double a = viscous / inertia;
  const double w_ss = net / viscous;
  const double c = w0 - w_ss;
  const double e1 = std::exp(-a * t);
  const double i1 = (1 - e1) / a;                          // integral of exp(-a t)
  const double i2 = (1 - std::exp(-2 * a * t)) / (2 * a);  // integral of exp(-2 a t)
  return {w_ss + c * e1, w_ss * t + c * i1, viscous * (w_ss * w_ss * t + 2 * w_ss * c * i1 + c * c * i2)};
}

// When a rotor slowing under `net` (opposite to w0) stops.
double time_to_stop(double w0, double net, double inertia, double viscous) {
  if (viscous <= 0) return -w0 * inertia / net;
  const double w_ss = net / viscous;
  return -(inertia / viscous) * std::log(w_ss / (w_ss - w0));
}

// A compliant coupling is integrated in steps this fine: the resonance turns at most this
// many radians per step (the symplectic step's energy error stays well under 1%).
constexpr double kCouplingStepRadians = 0.005;
// The stiffest coupling the model runs: above this the masses are rigid for any servo.
constexpr double kHighestResonanceHz = 5000;

// 1/J_motor + 1/J_load: how the coupling's torque accelerates the two apart.
double coupled_mobility(const MotorParams& p) {
  return 1 / p.inertia_kgm2 + 1 / reflected_load_inertia(p);
}

}  // namespace

double reflected_load_inertia(const MotorParams& p) {
  const double radius = p.machine.lead_m_per_turn / kTwoPi;  // metres of travel per radian
  return p.machine.load_inertia_kgm2 + p.machine.mass_kg * radius * radius;
}

double total_inertia(const MotorParams& p) {
  return p.inertia_kgm2 + reflected_load_inertia(p);
}

bool compliant(const MotorParams& p) {
  return p.machine.stiffness_nm_per_rad > 0 && reflected_load_inertia(p) > 0;
}

std::optional<double> resonance_hz(const MotorParams& p) {
  if (!compliant(p)) return std::nullopt;
  return std::sqrt(p.machine.stiffness_nm_per_rad * coupled_mobility(p)) / kTwoPi;
}

double flux_linkage(const MotorParams& p) {
  return p.torque_constant_nm_per_a / (1.5 * p.pole_pairs);
}

namespace {
void validate_machine(const MotorParams& p) {
  const auto non_negative = [](double v) { return v >= 0 && std::isfinite(v); };
  const MachineParams& m = p.machine;
  require(non_negative(m.lead_m_per_turn), "machine.lead must not be negative");
  require(non_negative(m.mass_kg), "machine.mass must not be negative");
  require(non_negative(m.load_inertia_kgm2), "machine.load_inertia must not be negative");
  require(non_negative(m.stiffness_nm_per_rad), "machine.stiffness must not be negative");
  require(non_negative(m.damping_nm_per_rad_s), "machine.damping must not be negative");
  require(m.mass_kg == 0 || m.lead_m_per_turn > 0,
          "machine.mass needs machine.lead (the travel per motor turn) to reach the motor shaft");
  require(m.stiffness_nm_per_rad == 0 || reflected_load_inertia(p) > 0,
          "machine.stiffness couples a load: give machine.mass or machine.load_inertia");
  require(m.damping_nm_per_rad_s == 0 || m.stiffness_nm_per_rad > 0,
          "machine.damping belongs to a compliant coupling: give machine.stiffness");
  if (const auto f = resonance_hz(p); f && p.inertia_kgm2 > 0)
    require(*f <= kHighestResonanceHz,
            "machine.stiffness puts the resonance at " + std::to_string(static_cast<long>(*f)) +
                " Hz, above the model's " + std::to_string(static_cast<long>(kHighestResonanceHz)) +
                " Hz: a coupling that stiff is rigid for any servo; leave the stiffness out");
}
}  // namespace

void validate(const MotorParams& p) {
  const auto positive = [](double v) { return v > 0 && std::isfinite(v); };
  const auto non_negative = [](double v) { return v >= 0 && std::isfinite(v); };
  require(p.pole_pairs > 0, "pole_pairs must be a whole number of at least 1");
  require(positive(p.winding.resistance_ohm), "resistance must be positive");
  require(positive(p.winding.inductance_h), "inductance must be positive");
  require(positive(p.torque_constant_nm_per_a), "torque_constant must be positive");
  require(positive(p.inertia_kgm2), "inertia must be positive");
  require(non_negative(p.viscous_nm_per_rad_s), "friction.viscous must not be negative");
  require(non_negative(p.coulomb_nm), "friction.coulomb must not be negative");
  require(non_negative(p.cogging_nm), "cogging.torque must not be negative");
  require(p.cogging_periods_per_turn >= 0, "cogging.periods_per_turn must not be negative");
  require(p.cogging_nm == 0 || p.cogging_periods_per_turn > 0,
          "cogging.periods_per_turn must be at least 1 when there is a cogging torque");
  require(std::isfinite(p.load_nm), "load must be a finite torque");
  require(non_negative(p.brake_torque_nm), "brake.torque must not be negative");
  require(!p.max_speed_rad_s || positive(*p.max_speed_rad_s), "max_speed must be positive");
  if (p.encoder) {
    require(p.encoder->counts_per_turn > 0, "encoder.counts_per_turn must be positive");
    require(p.encoder->direction == 1 || p.encoder->direction == -1, "encoder.direction must be 1 or -1");
  }
  validate_machine(p);
  if (p.halls && p.halls->bldc_pattern)
    require(known_bldc_pattern(*p.halls->bldc_pattern),
            "halls.pattern " + std::to_string(*p.halls->bldc_pattern) +
                " is not known to this tool (only bldc's default, 25); give halls.placement instead");
}

Motor::Motor(MotorParams params, double pwm_hz, int substeps)
    : params_(std::move(params)), period_(1.0 / pwm_hz), substeps_(substeps), winding_(params_.winding, 0) {
  validate(params_);
  require(pwm_hz > 0 && std::isfinite(pwm_hz), "the PWM rate must be positive");
  require(substeps > 0, "the number of sub-steps must be positive");
  winding_.set_params(params_.winding, flux_linkage(params_));
  update_outputs();
}

void Motor::set_params(const MotorParams& params) {
  validate(params);
  const bool was_compliant = compliant(params_);
  params_ = params;
  if (was_compliant && !compliant(params_)) {
    // The load locks onto the rotor with the momentum they had (the spring's energy is gone).
    const double jm = params_.inertia_kgm2, jl = reflected_load_inertia(params_);
    state_.speed_rad_s = (jm * state_.speed_rad_s + jl * load_speed_) / (jm + jl);
    load_angle_rad_ = angle_rad_;
    load_speed_ = state_.speed_rad_s;
  }
  winding_.set_params(params_.winding, flux_linkage(params_));
  update_outputs();
}

void Motor::command(const DriveCommand& drive) {
  if (!drive.output_on && drive_.output_on) {
    // The bridge switches off: the current has nowhere to go (the diodes' brief
    // freewheeling into the bus is not modelled) and the loop starts afresh.
    winding_.set_current({});
    loop_.reset();
    applied_ab_ = {};
  }
  drive_ = drive;
  update_outputs();
}

void Motor::step(double dt) {
  if (!(dt > 0)) return;
  carry_s_ += dt;
  // A period is due when the carried time reaches it (with float noise tolerated).
  while (carry_s_ >= period_ * (1 - 1e-9)) {
    carry_s_ -= period_;
    run_period();
  }
  if (carry_s_ < 0) carry_s_ = 0;
}

void Motor::run_period() {
  Dq next_ab;
  if (drive_.output_on) {
    // The controller samples the phase currents and computes next period's voltage.
    const double electrical = params_.pole_pairs * angle_rad_;
    const double frame = drive_.frame_follows_rotor ? electrical : drive_.frame_angle_rad;
    const Dq measured = rotate(rotate(winding_.current(), electrical), -frame);
    const Dq error{drive_.current_a.d - measured.d, drive_.current_a.q - measured.q};
    const auto out =
        loop_.update(error, drive_.d_gains, drive_.q_gains, period_, voltage_limit(drive_.bus_voltage_v));
    next_ab = rotate(out.voltage, frame);
    state_.voltage_limited = out.limited;
  } else {
    state_.voltage_limited = false;
  }
  const double h = period_ / substeps_;
  for (int k = 0; k < substeps_; ++k) substep(applied_ab_, h);
  applied_ab_ = next_ab;  // the computation delay: applied during the next period
  ++periods_;
  state_.time_s = static_cast<double>(periods_) * period_;
  update_outputs();
  check_protection();
}

void Motor::substep(Dq voltage_ab, double h) {
  const double electrical = params_.pole_pairs * angle_rad_;
  const double omega_e = params_.pole_pairs * state_.speed_rad_s;
  const Dq i0 = winding_.current();
  const Dq v = drive_.output_on ? rotate(voltage_ab, -electrical) : Dq{};
  advance_rotor(params_.torque_constant_nm_per_a * i0.q, h);
  if (drive_.output_on) winding_.step(v, omega_e, h);
  const Dq i1 = winding_.current();
  auto& e = state_.energy;
  // Trapezoids over the sub-step (3/2: peak phase quantities, three phases).
  e.electrical_in += 1.5 * (v.d * (i0.d + i1.d) + v.q * (i0.q + i1.q)) / 2 * h;
  e.copper_loss += 1.5 * params_.winding.resistance_ohm * (square(i0) + square(i1)) / 2 * h;
  state_.voltage_v = v;
}

// The rotor and, on a compliant coupling, the load. A rigid load is part of the rotor.
void Motor::advance_rotor(double torque_e, double h) {
  state_.torque_nm = torque_e;
  if (!compliant(params_)) {
    const double before = angle_rad_;
    advance_motor(torque_e, -params_.load_nm, total_inertia(params_), h);
    state_.energy.load_work += params_.load_nm * (angle_rad_ - before);
    load_angle_rad_ = angle_rad_;
    load_speed_ = state_.speed_rad_s;
    return;
  }
  // Two masses on a spring, in steps fine enough for the resonance and the damping. Over
  // each, both feel the coupling's torque at the step's predicted midpoint twist, held: the
  // rotor exactly under it (with its friction and stick), the load exactly under it and its
  // weight. That step preserves the spring's energy (no drift, however long it rings) and
  // depends only on the twist and the slip, not on how fast the axis travels.
  const double mobility = coupled_mobility(params_);
  const double turning =
      std::sqrt(params_.machine.stiffness_nm_per_rad * mobility) * h / kCouplingStepRadians;
  const double damping = params_.machine.damping_nm_per_rad_s * mobility * h / 0.01;
  const int steps = std::max(1, static_cast<int>(std::ceil(std::max(turning, damping))));
  const double hi = h / steps;
  for (int k = 0; k < steps; ++k) {
    const double slip_before = state_.speed_rad_s - load_speed_;
    const double pull =
        params_.machine.stiffness_nm_per_rad * (angle_rad_ - load_angle_rad_ + slip_before * hi / 2) +
        params_.machine.damping_nm_per_rad_s * slip_before;
    advance_motor(torque_e, -pull, params_.inertia_kgm2, hi);
    advance_load(pull, hi);
    const double slip = (slip_before + state_.speed_rad_s - load_speed_) / 2;
    state_.energy.coupling_loss += params_.machine.damping_nm_per_rad_s * slip * slip * hi;
  }
}

// The load under the coupling's pull and its weight, held over h.
void Motor::advance_load(double pull, double h) {
  const double acceleration = (pull - params_.load_nm) / reflected_load_inertia(params_);
  const double travelled = load_speed_ * h + acceleration * h * h / 2;
  load_speed_ += acceleration * h;
  load_angle_rad_ += travelled;
  state_.energy.load_work += params_.load_nm * travelled;
}

// The rotor under the electromagnetic torque and an `external` one held over h (the load, or
// the coupling's pull), with its friction, cogging and brake.
void Motor::advance_motor(double torque_e, double external, double inertia, double h) {
  const double viscous = params_.viscous_nm_per_rad_s;
  const double coulomb = params_.coulomb_nm + (params_.brake_engaged ? params_.brake_torque_nm : 0);
  const double cogging = params_.cogging_nm > 0
                             ? -params_.cogging_nm * std::sin(params_.cogging_periods_per_turn * angle_rad_)
                             : 0;
  const double applied = torque_e + external + cogging;
  double w = state_.speed_rad_s;
  if (w == 0 && std::abs(applied) <= coulomb) {  // static friction (and the brake) hold
    state_.stuck = true;
    return;
  }
  state_.stuck = false;
  const double direction = w != 0 ? (w > 0 ? 1.0 : -1.0) : (applied > 0 ? 1.0 : -1.0);
  const double net = applied - direction * coulomb;
  Motion m = coast(w, net, inertia, viscous, h);
  if (m.speed * direction < 0) {  // friction stopped the rotor within the sub-step
    m = coast(w, net, inertia, viscous, time_to_stop(w, net, inertia, viscous));
    m.speed = 0;
  }
  auto& e = state_.energy;
  e.electromagnetic += torque_e * m.angle;
  e.friction_loss += coulomb * std::abs(m.angle);
  e.viscous_loss += m.viscous;
  e.cogging_work -= cogging * m.angle;
  angle_rad_ += m.angle;
  state_.speed_rad_s = m.speed;
  if (params_.max_speed_rad_s && std::abs(m.speed) > *params_.max_speed_rad_s) runaway_ = true;
}

void Motor::update_outputs() {
  state_.angle_turns = angle_rad_ / kTwoPi;
  state_.load_angle_turns = load_angle_rad_ / kTwoPi;
  state_.load_speed_rad_s = load_speed_;
  state_.machine_position_m = state_.load_angle_turns * params_.machine.lead_m_per_turn;
  const double electrical = params_.pole_pairs * angle_rad_;
  state_.electrical_angle_rad = wrap(electrical);
  state_.current_a = winding_.current();
  const Dq ab = rotate(state_.current_a, electrical);
  const double half_root3 = std::sqrt(3.0) / 2;
  state_.phase_a[0] = ab.d;
  state_.phase_a[1] = -ab.d / 2 + half_root3 * ab.q;
  state_.phase_a[2] = -ab.d / 2 - half_root3 * ab.q;
}

void Motor::check_protection() {
  if (drive_.phase_trip_a <= 0 || !drive_.output_on) return;
  unsigned tripped = 0;
  for (unsigned k = 0; k < 3; ++k)
    if (std::abs(state_.phase_a[k]) > drive_.phase_trip_a) tripped |= 1u << k;
  if (!tripped) return;
  overcurrent_ |= tripped;
  DriveCommand off = drive_;
  off.output_on = false;
  command(off);
}

unsigned Motor::take_overcurrent() {
  const unsigned tripped = overcurrent_;
  overcurrent_ = 0;
  return tripped;
}

bool Motor::take_runaway() {
  const bool ran = runaway_;
  runaway_ = false;
  return ran;
}

void Motor::set_sensor_faults(SensorFaults faults) {
  if (faults.encoder_lost && !sensor_faults_.encoder_lost) encoder_frozen_turns_ = state_.angle_turns;
  if (faults.hall_stuck && !sensor_faults_.hall_stuck) hall_frozen_electrical_ = state_.electrical_angle_rad;
  sensor_faults_ = faults;
}

double Motor::hall_frozen_turns() const {
  return hall_frozen_electrical_ / (2.0 * std::numbers::pi * params_.pole_pairs);
}

SensorReading Motor::read_sensors() const {
  SensorReading r;
  if (params_.encoder)
    r.encoder_count = encoder_count(*params_.encoder,
                                    sensor_faults_.encoder_lost ? encoder_frozen_turns_ : state_.angle_turns);
  if (params_.halls)
    r.hall_code = hall_code(
        *params_.halls, sensor_faults_.hall_stuck ? hall_frozen_electrical_ : state_.electrical_angle_rad);
  return r;
}

double Motor::kinetic_energy_j() const {
  // A rigid load turns with the rotor (load_speed_ is the rotor's then).
  return 0.5 * params_.inertia_kgm2 * state_.speed_rad_s * state_.speed_rad_s +
         0.5 * reflected_load_inertia(params_) * load_speed_ * load_speed_;
}

double Motor::spring_energy_j() const {
  if (!compliant(params_)) return 0;
  const double twist = angle_rad_ - load_angle_rad_;
  return 0.5 * params_.machine.stiffness_nm_per_rad * twist * twist;
}

double Motor::magnetic_energy_j() const {
  return 0.75 * params_.winding.inductance_h * square(winding_.current());
}

}  // namespace i20::motor
