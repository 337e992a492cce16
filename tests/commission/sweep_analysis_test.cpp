// SPDX-License-Identifier: GPL-2.0-or-later
// The analysis on sweeps of healthy synthetic motors: every Hall sequence bldc accepts, both
// encoder directions, 60 and 120 degree layouts, 1-8 pole pairs, 500-10000 counts per turn,
// and the disturbances a real rotor brings (friction lag, backlash, cogging, Hall hysteresis).
#include <gtest/gtest.h>

#include "commission/analyse.hpp"
#include "commission/synthetic.hpp"
#include "error/error.hpp"
#include "truth.hpp"

using namespace i20::commission;
using namespace i20::commission::testing;

namespace {

std::size_t row_of_pattern_25() {
  return *find_hall_row(bldc_pattern_25());
}

SyntheticMotor healthy_motor() {
  SyntheticMotor m;
  m.pole_pairs = 4;
  m.counts_per_turn = 4000;
  m.index_electrical_deg = 123.4;
  m.initial_count = 1'000'000;
  m.hall_row = row_of_pattern_25();
  return m;
}

SweepPlan plan_for(const SyntheticMotor& m) {
  SweepPlan plan;
  plan.sweep_turns = m.pole_pairs + 1.5;  // the index passes each way
  return plan;
}

CommutationResult run(const SyntheticMotor& m, const AnalysisOptions& options, std::uint64_t seed = 1) {
  const auto samples = synthetic_sweep(m, plan_for(m), seed);
  return analyse(samples, options);
}

AnalysisOptions given_pole_pairs(const SyntheticMotor& m) {
  AnalysisOptions o;
  o.pole_pairs = m.pole_pairs;
  return o;
}

AnalysisOptions given_counts(const SyntheticMotor& m) {
  AnalysisOptions o;
  o.counts_per_turn = m.counts_per_turn;
  return o;
}

TEST(Analyse, HealthyMotorGivesEveryValue) {
  const SyntheticMotor m = healthy_motor();
  const auto r = run(m, given_counts(m));
  EXPECT_TRUE(r.problems.empty()) << problems_text(r);
  EXPECT_TRUE(wrong_values(r, m).empty());
  ASSERT_TRUE(r.pole_pairs && r.encoder_direction && r.counts_per_electrical_turn && r.encoder_offset_counts);
  EXPECT_EQ(r.pole_pairs->value, 4);
  EXPECT_EQ(r.encoder_direction->value, 1);
  EXPECT_NEAR(r.counts_per_electrical_turn->value, 1000.0, 1.0);
  // At the index the rotor is at 123.4 degrees; electrical zero is 236.6 degrees (657 counts) on.
  EXPECT_NEAR(r.index_electrical_angle_deg->value, 123.4, 1.0);
  EXPECT_NEAR(static_cast<double>(r.encoder_offset_counts->value), 657.2, 3.0);
  EXPECT_NEAR(r.encoder_offset_deg->value, 236.6, 1.0);
  ASSERT_TRUE(r.hall.bldc_pattern);
  EXPECT_EQ(r.hall.bldc_pattern->value, 25);
  EXPECT_EQ(r.hall.layout->value, HallLayout::Deg120);
  ASSERT_EQ(r.hall.states.size(), 6u);
  ASSERT_EQ(r.hall.edges.size(), 6u);
  for (const HallStateAngle& s : r.hall.states) {
    EXPECT_LT(circular_error_deg(s.centre_deg.value, 60.0 * s.bldc_sector), 1.0);
    EXPECT_FALSE(s.centre_deg.how.empty());
  }
  for (const HallEdgeAngle& e : r.hall.edges) {
    EXPECT_LT(
        circular_error_deg(e.angle_deg.value, std::round((e.angle_deg.value - 30.0) / 60.0) * 60.0 + 30.0),
        1.0);
  }
  for (const HallSensorFinding& s : r.hall.sensors) EXPECT_EQ(s.condition, SensorCondition::Ok);
}

TEST(Analyse, ReversedEncoderGivesNegativeScaleAndTheMirroredOffset) {
  SyntheticMotor m = healthy_motor();
  m.encoder_direction = -1;
  const auto r = run(m, given_counts(m));
  EXPECT_TRUE(wrong_values(r, m).empty());
  ASSERT_TRUE(r.encoder_direction && r.encoder_offset_counts);
  EXPECT_EQ(r.encoder_direction->value, -1);
  // Counting backwards, zero lies 123.4 degrees (343 counts) on from the index.
  EXPECT_NEAR(static_cast<double>(r.encoder_offset_counts->value), 342.8, 3.0);
}

// Every one of the 48 sequences, with both encoder directions: the sequence and layout are
// found; bldc's number is given only for 25, and every other map gets the rewiring to 25.
TEST(Analyse, FindsEveryHallSequenceBothDirections) {
  for (std::size_t row = 0; row < hall_table().size(); ++row) {
    for (int direction : {1, -1}) {
      SyntheticMotor m = healthy_motor();
      m.pole_pairs = 2;
      m.counts_per_turn = 2000;
      m.hall_row = row;
      m.encoder_direction = direction;
      m.index_electrical_deg = 17.0 * static_cast<double>(row);
      const auto r = run(m, given_counts(m), row);
      SCOPED_TRACE("row " + std::to_string(row) + " direction " + std::to_string(direction));
      EXPECT_TRUE(wrong_values(r, m).empty());
      ASSERT_TRUE(r.hall.sequence) << problems_text(r);
      EXPECT_EQ(r.hall.sequence->value, hall_table()[row].sequence);
      EXPECT_EQ(r.hall.layout->value, hall_table()[row].layout);
      ASSERT_TRUE(r.hall.bldc_pattern) << problems_text(r);
      EXPECT_EQ(r.hall.bldc_pattern->value, *hall_table()[row].bldc_pattern);
      EXPECT_FALSE(r.has(ProblemKind::PatternNumberUnknown));
      ASSERT_TRUE(r.hall.rewiring_to_25);
      EXPECT_EQ(r.problems.size(), 0u) << problems_text(r);
    }
  }
}

TEST(Analyse, NamesTheMiddleSensorOfASixtyDegreeLayout) {
  SyntheticMotor m = healthy_motor();
  // Sensors 60 degrees apart with hall2 in the middle leave 010 and 101 unused.
  for (std::size_t row = 0; row < hall_table().size(); ++row) {
    if (hall_table()[row].unused_low == 0b010) m.hall_row = row;
  }
  const auto r = run(m, given_counts(m));
  ASSERT_TRUE(r.hall.layout) << problems_text(r);
  EXPECT_EQ(r.hall.layout->value, HallLayout::Deg60);
  EXPECT_EQ(r.hall.middle_sensor_of_60, 2);
  AnalysisOptions expecting_120 = given_counts(m);
  expecting_120.expected_hall_layout = HallLayout::Deg120;
  EXPECT_TRUE(run(m, expecting_120).has(ProblemKind::HallLayoutUnexpected));
}

// 1-8 pole pairs, 500-10000 counts per turn, given either the pole pairs or the counts.
TEST(Analyse, PolePairsAndCountsPerTurnAcrossTheRange) {
  for (int pole_pairs = 1; pole_pairs <= 8; ++pole_pairs) {
    for (std::int64_t counts : {500, 1024, 2000, 2500, 4096, 8000, 10000}) {
      SyntheticMotor m = healthy_motor();
      m.pole_pairs = pole_pairs;
      m.counts_per_turn = counts;
      m.index_electrical_deg = 37.0 * pole_pairs + static_cast<double>(counts % 360);
      SCOPED_TRACE(std::to_string(pole_pairs) + " pole pairs, " + std::to_string(counts) + " counts");
      const auto by_counts = run(m, given_counts(m), static_cast<std::uint64_t>(counts + pole_pairs));
      EXPECT_TRUE(wrong_values(by_counts, m).empty());
      ASSERT_TRUE(by_counts.pole_pairs) << problems_text(by_counts);
      EXPECT_EQ(by_counts.pole_pairs->value, pole_pairs);
      ASSERT_TRUE(by_counts.encoder_offset_counts) << problems_text(by_counts);

      const auto by_poles = run(m, given_pole_pairs(m), static_cast<std::uint64_t>(counts * pole_pairs));
      EXPECT_TRUE(wrong_values(by_poles, m).empty());
      ASSERT_TRUE(by_poles.counts_per_turn) << problems_text(by_poles);
      EXPECT_NEAR(by_poles.counts_per_turn->value, static_cast<double>(counts), 0.5);
    }
  }
}

TEST(Analyse, WithNeitherGivenTheIndexMarksATurnGiveTheCounts) {
  SyntheticMotor m = healthy_motor();
  m.pole_pairs = 2;
  SweepPlan plan = plan_for(m);
  plan.sweep_turns = 2.0 * m.pole_pairs + 1.0;  // two index passes each way
  const auto r = analyse(synthetic_sweep(m, plan, 3), {});
  EXPECT_TRUE(wrong_values(r, m).empty());
  ASSERT_TRUE(r.counts_per_turn && r.pole_pairs) << problems_text(r);
  EXPECT_EQ(r.counts_per_turn->value, 4000.0);
  EXPECT_EQ(r.pole_pairs->value, 2);

  plan.sweep_turns = m.pole_pairs + 1.5;
  const auto short_sweep = analyse(synthetic_sweep(m, plan, 3), {});
  if (!short_sweep.pole_pairs) {
    EXPECT_TRUE(short_sweep.has(ProblemKind::NeedPolePairsOrCounts));
  }
  EXPECT_TRUE(wrong_values(short_sweep, m).empty());
}

// Friction makes the rotor trail the command, backlash lets the encoder trail the rotor,
// cogging ripples the rotor, Hall sensors switch late each way: sweeping both ways and
// averaging cancels the first, second and fourth; averaging whole turns the third.
TEST(Analyse, FrictionBacklashCoggingAndHysteresisCancel) {
  SyntheticMotor m = healthy_motor();
  m.friction_lag_deg = 25.0;
  m.backlash_deg = 6.0;
  m.cogging_deg = 4.0;
  m.cogging_periods_per_turn = 24;
  m.hall_hysteresis_deg = 6.0;
  m.sensor_error_deg = {2.0, -1.5, 1.0};
  m.hall_offset_deg = 5.0;
  const auto r = run(m, given_counts(m));
  EXPECT_TRUE(r.problems.empty()) << problems_text(r);
  EXPECT_TRUE(wrong_values(r, m).empty());
  ASSERT_TRUE(r.index_electrical_angle_deg && r.friction_lag_deg);
  EXPECT_LT(offset_error_deg(r, m), 2.0);
  // The encoder sees the friction lag plus half the coupling's play.
  EXPECT_NEAR(r.friction_lag_deg->value, m.friction_lag_deg + m.backlash_deg / 2.0, 2.0);
  ASSERT_TRUE(r.hall.offset_from_bldc_sectors_deg);
  EXPECT_NEAR(r.hall.offset_from_bldc_sectors_deg->value, 5.0 + (2.0 - 1.5 + 1.0) / 3.0, 1.0);
  // Against the encoder's angle, the play shows as negative hysteresis.
  for (const HallEdgeAngle& e : r.hall.edges) {
    EXPECT_NEAR(e.hysteresis_deg, m.hall_hysteresis_deg / 2.0 - m.backlash_deg / 2.0, 1.0);
  }
}

// A coarse encoder (80.5 counts per electrical turn) read over a short sweep samples some
// angles more often than others; a sensor must not look noisy for it (random motor 529, seed 3).
TEST(Analyse, CoarseEncoderOnAShortSweepDoesNotMakeSensorsNoisy) {
  SyntheticMotor m = healthy_motor();
  m.pole_pairs = 8;
  m.counts_per_turn = 644;
  m.has_index = false;
  m.backlash_deg = 3.8;
  m.friction_lag_deg = 13.7;
  m.hall_hysteresis_deg = 3.6;
  m.vibration_deg = 0.75;
  SweepPlan plan;
  plan.sweep_turns = 1.82;
  plan.turns_per_s = 1.13;
  plan.align_turns = 0.53;
  const auto r = analyse(synthetic_sweep(m, plan, 529), given_counts(m));
  for (const HallSensorFinding& s : r.hall.sensors) EXPECT_EQ(s.condition, SensorCondition::Ok) << s.how;
  EXPECT_TRUE(wrong_values(r, m).empty());
  EXPECT_TRUE(r.hall.bldc_pattern) << problems_text(r);
}

TEST(Analyse, RotorVibrationAveragesOut) {
  SyntheticMotor m = healthy_motor();
  m.vibration_deg = 1.5;
  m.friction_lag_deg = 10.0;
  m.hall_hysteresis_deg = 2.0;
  const auto r = run(m, given_counts(m), 31);
  EXPECT_TRUE(r.problems.empty()) << problems_text(r);
  EXPECT_TRUE(wrong_values(r, m).empty());
  ASSERT_TRUE(r.index_electrical_angle_deg);
  EXPECT_LT(offset_error_deg(r, m), 1.0);
  for (const HallSensorFinding& s : r.hall.sensors) EXPECT_EQ(s.condition, SensorCondition::Ok);
}

TEST(Analyse, OptionsOutOfRangeAreUsageErrors) {
  const SyntheticMotor m = healthy_motor();
  const auto samples = synthetic_sweep(m, plan_for(m), 32);
  AnalysisOptions no_poles;
  no_poles.pole_pairs = 0;
  EXPECT_THROW(analyse(samples, no_poles), i20::UsageError);
  AnalysisOptions negative_counts;
  negative_counts.counts_per_turn = -2000;
  EXPECT_THROW(analyse(samples, negative_counts), i20::UsageError);
}

TEST(Analyse, CommandThatWrapsEachTurnIsUnwrapped) {
  const SyntheticMotor m = healthy_motor();
  auto samples = synthetic_sweep(m, plan_for(m), 4);
  for (Sample& s : samples) s.commanded_electrical_turns = wrap_turns(s.commanded_electrical_turns);
  const auto r = analyse(samples, given_counts(m));
  EXPECT_TRUE(r.problems.empty()) << problems_text(r);
  EXPECT_TRUE(wrong_values(r, m).empty());
}

TEST(Analyse, HallStatesHalfWayBetweenSectorsGiveNoPattern) {
  SyntheticMotor m = healthy_motor();
  m.hall_offset_deg = 29.0;
  const auto r = run(m, given_counts(m));
  EXPECT_TRUE(r.has(ProblemKind::HallBetweenSectors)) << problems_text(r);
  EXPECT_FALSE(r.hall.sequence);
  EXPECT_FALSE(r.hall.bldc_pattern);
}

}  // namespace
