// SPDX-License-Identifier: GPL-2.0-or-later
// The values a bldc fragment needs, and the proof that they commutate: bldc's sinusoidal
// rotor angle, frac(((raw - index - encoder-offset) * poles/2) / scale) in its integer
// arithmetic, computed with the found settings, follows the synthetic rotor's true angle.
#include "commission/bldc_settings.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "commission/analyse.hpp"
#include "commission/synthetic.hpp"
#include "truth.hpp"

using namespace i20::commission;
using namespace i20::commission::testing;

namespace {

// bldc case 0x02 for qi/qhi once homed (offset-measured = the count at the index).
double bldc_rotor_angle(std::int64_t raw, std::int64_t at_index, const BldcSettings& s) {
  const std::int64_t scaled = (raw - at_index - *s.encoder_offset) * *s.poles / 2;
  return wrap_turns(static_cast<double>(scaled) / static_cast<double>(*s.scale));
}

void expect_commutates(const SyntheticMotor& m, const CommutationResult& r, const BldcSettings& s) {
  const auto count = [&](double mechanical) {
    return m.initial_count + static_cast<std::int64_t>(std::floor(
                                 m.encoder_direction * static_cast<double>(m.counts_per_turn) * mechanical));
  };
  const std::int64_t at_index = count(m.index_mechanical_turns);
  const double count_deg = 360.0 / true_counts_per_electrical_turn(m);
  double worst = 0;
  for (int i = 0; i < 1000; ++i) {
    const double mechanical = m.index_mechanical_turns - 1.0 + 3.0 * i / 1000.0;
    const double truth =
        m.pole_pairs * (mechanical - m.index_mechanical_turns) + m.index_electrical_deg / 360.0;
    worst = std::max(
        worst, circular_error_deg(bldc_rotor_angle(count(mechanical), at_index, s) * 360.0, truth * 360.0));
  }
  EXPECT_LE(worst, r.index_electrical_angle_deg->uncertainty + 2.0 * count_deg);
  EXPECT_LT(worst, 5.0);
}

TEST(BldcSettings, FoundSettingsCommutateTheMotorBothDirections) {
  for (int direction : {1, -1}) {
    SyntheticMotor m;
    m.pole_pairs = 5;
    m.counts_per_turn = 8000;
    m.encoder_direction = direction;
    m.index_electrical_deg = 311.0;
    m.initial_count = -40'000;
    m.hall_row = *find_hall_row(bldc_pattern_25());
    m.friction_lag_deg = 10.0;
    m.cogging_deg = 2.0;
    m.cogging_periods_per_turn = 30;
    SweepPlan plan;
    plan.sweep_turns = 6.5;
    AnalysisOptions options;
    options.pole_pairs = 5;
    options.counts_per_turn = 8000;
    const auto r = analyse(synthetic_sweep(m, plan, 21), options);
    const BldcSettings s = bldc_settings(r);
    EXPECT_TRUE(s.missing.empty());
    ASSERT_TRUE(s.pattern && s.poles && s.scale && s.encoder_offset);
    EXPECT_EQ(*s.pattern, 25);
    EXPECT_FALSE(s.hall_rewiring);
    EXPECT_EQ(*s.poles, 10) << "bldc's poles counts poles, not pairs";
    EXPECT_EQ(*s.scale, direction * 8000);
    expect_commutates(m, r, s);
  }
}

TEST(BldcSettings, OtherPatternsComeAsTheirOwnBldcNumber) {
  SyntheticMotor m;
  m.hall_row = 0;
  ASSERT_TRUE(hall_table()[0].bldc_pattern);
  ASSERT_NE(*hall_table()[0].bldc_pattern, 25);
  SweepPlan plan;
  plan.sweep_turns = 5.5;
  AnalysisOptions options;
  options.counts_per_turn = m.counts_per_turn;
  const BldcSettings s = bldc_settings(analyse(synthetic_sweep(m, plan, 22), options));
  ASSERT_TRUE(s.pattern);
  EXPECT_EQ(*s.pattern, *hall_table()[0].bldc_pattern);
  EXPECT_FALSE(s.hall_rewiring) << "no rewiring is needed when bldc has the pattern";
}

// bldc's trapezoidal modes read the rotor angle from the Hall code through the pattern: with
// the pattern found (bldc's own number for the map, the sensors wired as they are) every
// sample's sector centre must be within half a sector of the rotor's true angle, for every
// one of the 48 maps.
TEST(BldcSettings, HallSettingsPutEveryMapWithinHalfASector) {
  const auto sequence_of = [](int pattern) {
    for (const HallTableRow& row : hall_table())
      if (row.bldc_pattern == pattern) return row.sequence;
    ADD_FAILURE() << "no row has bldc pattern " << pattern;
    return HallSequence{};
  };
  for (std::size_t row = 0; row < hall_table().size(); ++row) {
    SyntheticMotor m;
    m.pole_pairs = 3;
    m.counts_per_turn = 6000;
    m.hall_row = row;
    m.encoder_direction = row % 2 ? 1 : -1;
    SweepPlan plan;
    plan.sweep_turns = 4.5;
    AnalysisOptions options;
    options.counts_per_turn = m.counts_per_turn;
    const auto samples = synthetic_sweep(m, plan, 100 + row);
    const BldcSettings s = bldc_settings(analyse(samples, options));
    ASSERT_TRUE(s.pattern);
    EXPECT_FALSE(s.hall_rewiring);
    const HallSequence pattern = sequence_of(*s.pattern);
    double worst = 0;
    for (const Sample& sample : samples) {
      // No friction or play: the rotor's angle follows from the count (to one count).
      const double mechanical = static_cast<double>(sample.encoder_count - m.initial_count) /
                                (m.encoder_direction * static_cast<double>(m.counts_per_turn));
      const double truth =
          m.pole_pairs * (mechanical - m.index_mechanical_turns) + m.index_electrical_deg / 360.0;
      const auto* sector =
          std::find(pattern.code_at_sector.begin(), pattern.code_at_sector.end(), sample.hall_state);
      ASSERT_NE(sector, pattern.code_at_sector.end())
          << "row " << row << " code " << hall_code_text(sample.hall_state);
      const double bldc_angle = 60.0 * static_cast<double>(sector - pattern.code_at_sector.begin());
      worst = std::max(worst, circular_error_deg(bldc_angle, truth * 360.0));
    }
    EXPECT_LE(worst, 30.0 + 2.0 * 360.0 * m.pole_pairs / static_cast<double>(m.counts_per_turn))
        << "row " << row;
  }
}

TEST(BldcSettings, AnInexactCountsPerTurnGivesNoScale) {
  SyntheticMotor m;
  m.has_index = false;
  m.hall_row = 5;
  SweepPlan plan;
  plan.sweep_turns = 3.0;
  AnalysisOptions options;
  options.pole_pairs = m.pole_pairs;
  const auto r = analyse(synthetic_sweep(m, plan, 23), options);
  const BldcSettings s = bldc_settings(r);
  EXPECT_TRUE(s.poles);
  if (r.counts_per_turn->uncertainty > 0.5) {
    EXPECT_FALSE(s.scale);
    EXPECT_TRUE(r.has(ProblemKind::CountsPerTurnInexact));
  }
  EXPECT_FALSE(s.encoder_offset);
  EXPECT_EQ(s.missing.size(), s.scale ? 1u : 2u);
}

}  // namespace
