// SPDX-License-Identifier: GPL-2.0-or-later
// A synthetic motor and the commissioning sweep run on it, for the analysis' tests and
// benchmark (and later a virtual motor). Pure and seeded: the same seed gives the same samples.
//
// Model. The rotor's electrical angle is theta = pole_pairs * (m - index_mechanical_turns)
// + index_electrical_turns, m its mechanical position. The encoder counts
// initial_count + floor(direction * counts_per_turn * m_encoder), m_encoder trailing m through
// the coupling's backlash. The rotor follows the command through friction (it stays within
// friction_lag of the command and does not move until pushed: a play), plus a cogging ripple.
// The Hall sensors show the table row's code for the sector the rotor is in, each sensor with
// its own placement error and hysteresis, one sensor possibly noisy or stuck.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "commission/sample.hpp"

namespace i20::commission {

struct SyntheticMotor {
  int pole_pairs = 4;
  std::int64_t counts_per_turn = 2000;
  int encoder_direction = 1;                    // +1: counts rise as the electrical angle rises
  double index_electrical_deg = 0;              // the rotor's electrical angle at the index (the truth)
  double index_mechanical_turns = 0.37;         // where the index sits, from the encoder's count zero
  std::int64_t initial_count = 0;               // raw count at the encoder's mechanical zero
  double initial_rotor_electrical_turns = 0.3;  // where the rotor rests before the sweep
  bool has_index = true;
  bool encoder_connected = true;
  bool stalled = false;  // brake on, or the motor not connected

  std::size_t hall_row = 0;                  // the true Hall sequence: a row of hall_table()
  double hall_offset_deg = 0;                // all sectors' shift from bldc's centres
  std::array<double, 3> sensor_error_deg{};  // each sensor's own placement error
  double hall_hysteresis_deg = 0;            // full width: each edge shows half of it late
  int noisy_sensor = 0;                      // 1-3, 0 for none
  double noise_probability = 0;              // chance per sample that the noisy sensor reads wrong
  int stuck_sensor = 0;                      // 1-3, 0 for none
  bool stuck_high = true;

  double friction_lag_deg = 0;       // electrical
  double backlash_deg = 0;           // electrical play between rotor and encoder
  double cogging_deg = 0;            // ripple amplitude, electrical
  int cogging_periods_per_turn = 0;  // per mechanical turn
  double vibration_deg = 0;          // random rotor jitter each sample (standard deviation), electrical
};

// The procedure: hold at align_turns while the current ramps, then sweep_turns electrical
// turns forward and the same back, sampling every period.
struct SweepPlan {
  double period_s = 0.001;
  double align_s = 1.0;
  double ramp_s = 0.4;
  double align_turns = 0.0;
  double sweep_turns = 3.0;
  double turns_per_s = 1.0;
};

std::vector<Sample> synthetic_sweep(const SyntheticMotor& motor, const SweepPlan& plan, std::uint64_t seed);

// The truth, for judging the analysis: bldc's encoder-offset (not rounded) and the counts
// per electrical turn.
double true_encoder_offset_counts(const SyntheticMotor& motor);
double true_counts_per_electrical_turn(const SyntheticMotor& motor);

}  // namespace i20::commission
