// SPDX-License-Identifier: GPL-2.0-or-later
#include "commission/synthetic.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "commission/circular.hpp"
#include "commission/hall_table.hpp"

namespace i20::commission {

namespace {

constexpr double kDeg = 1.0 / 360.0;

// The command at time t.
double command_at(const SweepPlan& plan, double t) {
  if (t <= plan.align_s) return plan.align_turns;
  const double travelled = (t - plan.align_s) * plan.turns_per_s;
  if (travelled <= plan.sweep_turns) return plan.align_turns + travelled;
  return plan.align_turns + std::max(0.0, 2.0 * plan.sweep_turns - travelled);
}

class MotorState {
 public:
  MotorState(const SyntheticMotor& motor, const SweepPlan& plan, std::uint64_t seed)
      : motor_(motor), plan_(plan), random_(seed) {
    rotor_ = motor.initial_rotor_electrical_turns;
    played_ = rotor_;
    encoder_m_ = mechanical(rotor_);
  }

  Sample step(double t) {
    const double command = command_at(plan_, t);
    move_rotor(t, command);
    const double previous_encoder = encoder_m_;
    const double m = mechanical(rotor_);
    const double play = motor_.backlash_deg * kDeg / motor_.pole_pairs / 2.0;
    encoder_m_ = std::clamp(encoder_m_, m - play, m + play);
    Sample s;
    s.t_s = t;
    s.commanded_electrical_turns = command;
    s.encoder_count = motor_.encoder_connected ? count_at(encoder_m_) : motor_.initial_count;
    s.hall_state = hall_code();
    if (motor_.has_index && motor_.encoder_connected) latch_index(previous_encoder, encoder_m_, s);
    return s;
  }

 private:
  double mechanical(double electrical) const {
    return (electrical - motor_.index_electrical_deg * kDeg) / motor_.pole_pairs +
           motor_.index_mechanical_turns;
  }

  std::int64_t count_at(double m) const {
    return motor_.initial_count +
           static_cast<std::int64_t>(
               std::floor(motor_.encoder_direction * static_cast<double>(motor_.counts_per_turn) * m));
  }

  void move_rotor(double t, double command) {
    if (motor_.stalled) return;
    const double before = rotor_;
    // The rising current pulls the rotor to the nearest electrical equivalent of the command,
    // whole electrical turns from it; the rotor follows that equivalent from then on.
    const double equivalent = command + std::round(motor_.initial_rotor_electrical_turns - plan_.align_turns);
    if (t <= plan_.align_s) {
      const double pull = std::clamp(t / plan_.ramp_s, 0.0, 1.0);
      played_ =
          motor_.initial_rotor_electrical_turns + (equivalent - motor_.initial_rotor_electrical_turns) * pull;
    } else {
      const double lag = motor_.friction_lag_deg * kDeg;
      played_ = std::clamp(played_, equivalent - lag, equivalent + lag);
    }
    const double ripple =
        motor_.cogging_deg * kDeg *
        std::sin(2.0 * std::numbers::pi * motor_.cogging_periods_per_turn * mechanical(played_));
    std::normal_distribution<double> jitter(0.0, motor_.vibration_deg * kDeg);
    rotor_ = played_ + ripple + (motor_.vibration_deg > 0 ? jitter(random_) : 0.0);
    if (rotor_ > before) moving_ = 1;
    if (rotor_ < before) moving_ = -1;
  }

  HallCode hall_code() {
    const HallSequence& sequence = hall_table()[motor_.hall_row].sequence;
    std::bernoulli_distribution noise(motor_.noise_probability);
    HallCode code = 0;
    for (int sensor = 1; sensor <= 3; ++sensor) {
      const HallCode bit = hall_bit(sensor);
      // A sensor switches late, in the direction of motion, by half its hysteresis.
      const double seen_at = rotor_ - (motor_.hall_offset_deg + motor_.sensor_error_deg[sensor - 1] +
                                       moving_ * motor_.hall_hysteresis_deg / 2.0) *
                                          kDeg;
      const auto sector = static_cast<std::size_t>(std::floor(wrap_turns(seen_at + 1.0 / 12.0) * 6.0)) % 6;
      bool high = (sequence.code_at_sector[sector] & bit) != 0;
      if (sensor == motor_.noisy_sensor && noise(random_)) high = !high;
      if (sensor == motor_.stuck_sensor) high = motor_.stuck_high;
      if (high) code |= bit;
    }
    return code;
  }

  // hm2 latches the count at the index edge; the procedure re-arms the latch every period.
  void latch_index(double from, double to, Sample& s) const {
    const double low = std::min(from, to), high = std::max(from, to);
    const double first = std::ceil(low - motor_.index_mechanical_turns) + motor_.index_mechanical_turns;
    if (first <= high && first > low) {
      s.index_seen = true;
      s.latched_count = count_at(first);
    }
  }

  const SyntheticMotor& motor_;
  const SweepPlan& plan_;
  std::mt19937_64 random_;
  double rotor_ = 0;   // electrical turns
  double played_ = 0;  // the rotor before the cogging ripple
  double encoder_m_ = 0;
  int moving_ = 1;
};

}  // namespace

std::vector<Sample> synthetic_sweep(const SyntheticMotor& motor, const SweepPlan& plan, std::uint64_t seed) {
  MotorState state(motor, plan, seed);
  const double duration = plan.align_s + 2.0 * plan.sweep_turns / plan.turns_per_s;
  const auto periods = static_cast<std::size_t>(std::ceil(duration / plan.period_s));
  std::vector<Sample> samples;
  samples.reserve(periods + 1);
  for (std::size_t i = 0; i <= periods; ++i)
    samples.push_back(state.step(static_cast<double>(i) * plan.period_s));
  return samples;
}

double true_counts_per_electrical_turn(const SyntheticMotor& motor) {
  return static_cast<double>(motor.counts_per_turn) / motor.pole_pairs;
}

double true_encoder_offset_counts(const SyntheticMotor& motor) {
  return wrap_turns(-motor.encoder_direction * motor.index_electrical_deg * kDeg) *
         true_counts_per_electrical_turn(motor);
}

}  // namespace i20::commission
