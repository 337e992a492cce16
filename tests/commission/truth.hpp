// SPDX-License-Identifier: GPL-2.0-or-later
// Judging an analysis against the synthetic motor it ran on: every value it gives must be the
// truth (continuous values within their stated uncertainty); a value it leaves out must come
// with a problem saying why.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "commission/analyse.hpp"
#include "commission/circular.hpp"
#include "commission/synthetic.hpp"

namespace i20::commission::testing {

inline double circular_error_deg(double a_deg, double b_deg) {
  return std::abs(wrap_signed((a_deg - b_deg) / 360.0)) * 360.0;
}

inline double offset_error_deg(const CommutationResult& r, const SyntheticMotor& m) {
  return circular_error_deg(r.index_electrical_angle_deg->value, m.index_electrical_deg);
}

// Values that contradict the truth, each named.
inline std::vector<std::string> wrong_values(const CommutationResult& r, const SyntheticMotor& m) {
  std::vector<std::string> wrong;
  const auto check = [&](bool ok, const std::string& what) {
    if (!ok) wrong.push_back(what);
  };
  if (r.encoder_direction) check(r.encoder_direction->value == m.encoder_direction, "encoder direction");
  if (r.pole_pairs)
    check(r.pole_pairs->value == m.pole_pairs, "pole pairs " + std::to_string(r.pole_pairs->value));
  if (r.counts_per_turn) {
    check(std::abs(r.counts_per_turn->value - static_cast<double>(m.counts_per_turn)) <=
              r.counts_per_turn->uncertainty + 0.5,
          "counts per turn " + std::to_string(r.counts_per_turn->value));
  }
  if (r.counts_per_electrical_turn) {
    check(std::abs(r.counts_per_electrical_turn->value - true_counts_per_electrical_turn(m)) <=
              r.counts_per_electrical_turn->uncertainty,
          "counts per electrical turn " + std::to_string(r.counts_per_electrical_turn->value));
  }
  if (r.index_electrical_angle_deg) {
    check(offset_error_deg(r, m) <= r.index_electrical_angle_deg->uncertainty,
          "index angle " + std::to_string(r.index_electrical_angle_deg->value) + " +/- " +
              std::to_string(r.index_electrical_angle_deg->uncertainty) + " (truth " +
              std::to_string(m.index_electrical_deg) + ")");
  }
  if (r.encoder_offset_counts) {
    const double cpet = true_counts_per_electrical_turn(m);
    const double error =
        std::abs(wrap_signed(
            (static_cast<double>(r.encoder_offset_counts->value) - true_encoder_offset_counts(m)) / cpet)) *
        cpet;
    check(error <= r.encoder_offset_counts->uncertainty + 0.5,
          "encoder-offset " + std::to_string(r.encoder_offset_counts->value) + " (truth " +
              std::to_string(true_encoder_offset_counts(m)) + ")");
  }
  const HallTableRow& row = hall_table()[m.hall_row];
  if (r.hall.sequence) check(r.hall.sequence->value == row.sequence, "Hall sequence");
  if (r.hall.layout) check(r.hall.layout->value == row.layout, "Hall layout");
  if (r.hall.bldc_pattern) check(row.bldc_pattern == r.hall.bldc_pattern->value, "bldc pattern");
  for (const HallSensorFinding& s : r.hall.sensors) {
    const bool stuck = s.condition == SensorCondition::StuckHigh || s.condition == SensorCondition::StuckLow;
    if (stuck) check(m.stuck_sensor == s.sensor, "hall" + std::to_string(s.sensor) + " called stuck");
    if (m.stuck_sensor == s.sensor) {
      check(s.condition == (m.stuck_high ? SensorCondition::StuckHigh : SensorCondition::StuckLow),
            "stuck hall" + std::to_string(s.sensor) + " not named");
    }
    if (s.condition == SensorCondition::Noisy) {
      check(m.noisy_sensor == s.sensor, "hall" + std::to_string(s.sensor) + " called noisy");
    }
  }
  return wrong;
}

inline std::string problems_text(const CommutationResult& r) {
  std::string text;
  for (const Problem& p : r.problems) text += p.message + "\n";
  return text;
}

}  // namespace i20::commission::testing
