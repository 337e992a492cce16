// SPDX-License-Identifier: GPL-2.0-or-later
#include "mechanics/axis_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "motor/error.hpp"
#include "motor/motor.hpp"

namespace i20::mechanics {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// One leg: from 0 to `distance` (either sign), a trapezoid, or a triangle when too short to
// reach the speed.
double leg(double t, double distance, double speed, double accel) {
  const double d = std::abs(distance), sign = distance < 0 ? -1 : 1;
  const double ta = std::min(speed / accel, std::sqrt(d / accel));
  const double reach = accel * ta;
  const double cruise = (d - accel * ta * ta) / reach;
  double s = 0;
  if (t <= 0)
    s = 0;
  else if (t < ta)
    s = 0.5 * accel * t * t;
  else if (t < ta + cruise)
    s = 0.5 * accel * ta * ta + reach * (t - ta);
  else if (t < 2 * ta + cruise)
    s = d - 0.5 * accel * (2 * ta + cruise - t) * (2 * ta + cruise - t);
  else
    s = d;
  return sign * s;
}

double leg_time(double distance, double speed, double accel) {
  const double d = std::abs(distance);
  const double ta = std::min(speed / accel, std::sqrt(d / accel));
  return 2 * ta + (d - accel * ta * ta) / (accel * ta);
}

// The 8I20's current loop as the design assumes it: PI cancelling the winding's pole at the
// bandwidth, on a 320 V bus, the rotor's own frame.
motor::DriveCommand current_command(const motor::MotorParams& p, double amps, double bandwidth_hz) {
  const double wc = kTwoPi * bandwidth_hz;
  motor::DriveCommand d;
  d.output_on = true;
  d.frame_follows_rotor = true;
  d.current_a = {0, amps};
  d.d_gains = d.q_gains = {p.winding.inductance_h * wc, p.winding.resistance_ohm * wc};
  d.bus_voltage_v = 320;
  return d;
}

}  // namespace

double MoveProfile::duration_s() const {
  return 2 * (leg_time(distance, speed, accel) + dwell_s);
}

double MoveProfile::position(double t) const {
  const double out = leg_time(distance, speed, accel) + dwell_s;
  return t < out ? leg(t, distance, speed, accel) : distance - leg(t - out, distance, speed, accel);
}

MoveTrace simulate_move(const motor::MotorParams& truth, const PidGains& g, double units_per_rad,
                        const MoveProfile& move, const LoopTiming& timing, double gain_scale) {
  if (!(units_per_rad > 0)) throw IdentifyError("a move needs the machine units per motor radian");
  if (!(move.distance != 0 && move.speed > 0 && move.accel > 0 && move.dwell_s >= 0))
    throw IdentifyError(
        "a move needs a distance, a positive speed and acceleration, and a dwell of 0 or more");
  const double T = timing.servo_period_s;
  motor::Motor m = [&] {
    try {
      return motor::Motor(truth);
    } catch (const motor::MotorError& e) {
      throw IdentifyError(e.what());
    }
  }();
  const auto position = [&] {
    if (!truth.encoder) return m.state().angle_turns * kTwoPi * units_per_rad;
    const double counts = static_cast<double>(truth.encoder->counts_per_turn) * truth.encoder->direction;
    return static_cast<double>(*m.read_sensors().encoder_count) / counts * kTwoPi * units_per_rad;
  };
  MoveTrace trace;
  double integral = 0, previous_error = 0, c1 = 0, c2 = 0, pending = 0, squares = 0;
  double s1 = 0, s2 = 0;  // the notch's state (biquad, transposed direct form II)
  const auto periods = static_cast<int>(std::ceil(move.duration_s() / T));
  for (int k = 0; k < periods; ++k) {
    const double t = k * T;
    const double c = move.position(t), x = position(), e = c - x;
    integral += e * T;
    const double derivative = k == 0 ? 0 : (e - previous_error) / T;
    const double ff1 = k == 0 ? 0 : (c - c1) / T, ff2 = k < 2 ? 0 : (c - 2 * c1 + c2) / (T * T);
    previous_error = e;
    c2 = c1;
    c1 = c;
    const double out = g.bias + gain_scale * (g.p * e + g.i * integral + g.d * derivative) + g.ff0 * c +
                       g.ff1 * ff1 + g.ff2 * ff2;
    m.command(
        current_command(truth, pending, timing.current_bandwidth_hz));  // last period's, one period late
    pending = std::clamp(out, -g.maxoutput, g.maxoutput);
    if (g.notch) {  // biquad on pid's output; the 8I20 holds MAXCURRENT (maxoutput) itself
      const double in = pending;
      pending = g.notch->n0 * in + s1;
      s1 = g.notch->n1 * in - g.notch->d1 * pending + s2;
      s2 = g.notch->n2 * in - g.notch->d2 * pending;
      pending = std::clamp(pending, -g.maxoutput, g.maxoutput);
    }
    m.step(T);
    trace.points.push_back({t, c, x, e, pending});
    trace.peak_error = std::max(trace.peak_error, std::abs(e));
    squares += e * e;
  }
  trace.rms_error = std::sqrt(squares / std::max(1, periods));
  const auto rest_from = static_cast<std::size_t>(std::max(0.0, (move.duration_s() - move.dwell_s / 4) / T));
  for (std::size_t k = rest_from; k < trace.points.size(); ++k)
    trace.rest_error = std::max(trace.rest_error, std::abs(trace.points[k].error));
  return trace;
}

Rehearsal rehearse_identification(const motor::MotorParams& truth, const Excitation& path,
                                  double inertia_guess, double friction_guess, double servo_period_s) {
  if (!truth.encoder) throw IdentifyError("a rehearsed identification needs the motor's encoder");
  const double T = servo_period_s;
  motor::Motor m(truth);
  const double w = kTwoPi * 4;  // the loop's bandwidth
  const double kp = std::max(inertia_guess * w * w, 10 * friction_guess / path.amplitude_rad());
  const double kd = 2 * 0.8 * std::sqrt(kp * inertia_guess), ki = kp * w / 5;
  const double smoothing = 1 - std::exp(-kTwoPi * 20 * T);
  const double counts = static_cast<double>(truth.encoder->counts_per_turn) * truth.encoder->direction;
  const double most = 0.9 * truth.torque_constant_nm_per_a * 10;  // 9 A's torque
  Rehearsal r;
  double integral = 0, previous = 0, speed = 0, torque = 0;
  for (int k = 0; k * T < path.duration_s(); ++k) {
    const double t = k * T;
    const double position = static_cast<double>(*m.read_sensors().encoder_count) / counts * kTwoPi;
    if (k > 0) speed += smoothing * ((position - previous) / T - speed);
    previous = position;
    const double error = path.position_rad(t) - position;
    integral += error * T;
    const double wanted = kp * error + kd * (path.speed_rad_s(t) - speed) + ki * integral;
    torque = std::clamp(torque + smoothing * (wanted - torque), -most, most);
    r.samples.push_back({t, position, torque});
    r.widest_rad = std::max(r.widest_rad, std::abs(m.state().angle_turns * kTwoPi));
    m.command(current_command(truth, torque / truth.torque_constant_nm_per_a, 1000));
    m.step(T);
  }
  return r;
}

AxisModel axis_model_of(const motor::MotorParams& truth, double units_per_rad, double max_current_a) {
  AxisModel a{.inertia_kgm2 = motor::total_inertia(truth),
              .viscous_nm_per_rad_s = truth.viscous_nm_per_rad_s,
              .coulomb_nm = truth.coulomb_nm,
              .bias_nm = truth.load_nm,
              .torque_constant_nm_per_a = truth.torque_constant_nm_per_a,
              .units_per_rad = units_per_rad,
              .max_current_a = max_current_a,
              .resonance_hz = motor::resonance_hz(truth)};
  if (a.resonance_hz) {
    a.rotor_inertia_kgm2 = truth.inertia_kgm2;
    const double mobility = 1 / truth.inertia_kgm2 + 1 / motor::reflected_load_inertia(truth);
    a.coupling_damping_ratio =
        truth.machine.damping_nm_per_rad_s / (2 * std::sqrt(truth.machine.stiffness_nm_per_rad / mobility));
  }
  return a;
}

motor::MotorParams random_vertical_axis(std::mt19937_64& random) {
  const auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(random);
  };
  motor::MotorParams p;
  p.name = "random vertical axis";
  p.pole_pairs = 4;
  p.winding = {1.9, 6.2e-3};
  p.torque_constant_nm_per_a = 0.45;
  p.inertia_kgm2 = 0.6e-4;
  p.cogging_nm = 0.01;
  p.cogging_periods_per_turn = 36;
  p.encoder = motor::EncoderDescription{};
  p.encoder->counts_per_turn = 10000;
  p.machine.lead_m_per_turn = 0.005;
  const double radius = 0.005 / kTwoPi;
  p.machine.mass_kg = uniform(1, 20) * p.inertia_kgm2 / (radius * radius);
  p.coulomb_nm = uniform(0.01, 0.08);
  p.viscous_nm_per_rad_s = uniform(0, 1e-3);
  p.load_nm = uniform(-0.5, 0.5);
  const double load = motor::reflected_load_inertia(p);
  const double share = p.inertia_kgm2 / (p.inertia_kgm2 + load);
  const double f_r = std::max(uniform(50, 400), 30 / std::sqrt(share));
  const double mobility = 1 / p.inertia_kgm2 + 1 / load;
  p.machine.stiffness_nm_per_rad = std::pow(kTwoPi * f_r, 2) / mobility;
  p.machine.damping_nm_per_rad_s = 2 * 0.05 * std::sqrt(p.machine.stiffness_nm_per_rad / mobility);
  return p;
}

}  // namespace i20::mechanics
