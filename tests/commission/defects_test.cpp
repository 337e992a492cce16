// SPDX-License-Identifier: GPL-2.0-or-later
// What the analysis says when it cannot tell: a stall, a silent encoder, a rotor that does
// not follow, wrong pole pairs or counts, no index, a stuck or noisy Hall sensor, a sweep too
// short. Each names the defect and leaves the values it cannot vouch for out.
#include <gtest/gtest.h>

#include "commission/analyse.hpp"
#include "commission/synthetic.hpp"
#include "truth.hpp"

using namespace i20::commission;
using namespace i20::commission::testing;

namespace {

SyntheticMotor motor() {
  SyntheticMotor m;
  m.pole_pairs = 3;
  m.counts_per_turn = 3000;
  m.index_electrical_deg = 200.0;
  m.hall_row = *find_hall_row(bldc_pattern_25());
  return m;
}

SweepPlan plan() {
  SweepPlan p;
  p.sweep_turns = 4.5;
  return p;
}

AnalysisOptions counts(std::int64_t cpr = 3000) {
  AnalysisOptions o;
  o.counts_per_turn = cpr;
  return o;
}

bool message_has(const CommutationResult& r, ProblemKind kind, const std::string& words) {
  for (const Problem& p : r.problems) {
    if (p.kind == kind && p.message.find(words) != std::string::npos) return true;
  }
  return false;
}

TEST(Defects, StallAsksAboutTheBrakeAndTheMotor) {
  SyntheticMotor m = motor();
  m.stalled = true;
  const auto r = analyse(synthetic_sweep(m, plan(), 1), counts());
  EXPECT_TRUE(message_has(r, ProblemKind::NoMotion, "no motion: is the brake released, the motor connected?"))
      << problems_text(r);
  EXPECT_FALSE(r.encoder_direction);
  EXPECT_FALSE(r.pole_pairs);
  EXPECT_FALSE(r.hall.sequence);
}

TEST(Defects, SilentEncoderIsNamedAndTheHallMapStillFound) {
  SyntheticMotor m = motor();
  m.encoder_connected = false;
  m.friction_lag_deg = 15.0;
  const auto r = analyse(synthetic_sweep(m, plan(), 2), counts());
  EXPECT_TRUE(r.has(ProblemKind::EncoderSilent)) << problems_text(r);
  EXPECT_FALSE(r.encoder_offset_counts);
  ASSERT_TRUE(r.hall.bldc_pattern) << problems_text(r);
  EXPECT_EQ(r.hall.bldc_pattern->value, 25);
  EXPECT_TRUE(wrong_values(r, m).empty());
}

TEST(Defects, RotorThatDoesNotComeBackDisagreesWithTheCommand) {
  const SyntheticMotor m = motor();
  auto samples = synthetic_sweep(m, plan(), 3);
  // Freeze the encoder from the turn-around on, as a brake that grabs would.
  std::size_t turn = 0;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (samples[i].commanded_electrical_turns < samples[i - 1].commanded_electrical_turns) {
      turn = i;
      break;
    }
  }
  ASSERT_GT(turn, 0u);
  for (std::size_t i = turn; i < samples.size(); ++i)
    samples[i].encoder_count = samples[turn - 1].encoder_count;
  const auto r = analyse(samples, counts());
  EXPECT_TRUE(r.has(ProblemKind::MoveDisagreesWithCommand)) << problems_text(r);
  EXPECT_FALSE(r.encoder_direction);
  EXPECT_FALSE(r.hall.sequence) << "no Hall map from a rotor that did not follow";
}

TEST(Defects, RotorThatSlipsAPoleDisagreesWithTheCommand) {
  const SyntheticMotor m = motor();
  auto samples = synthetic_sweep(m, plan(), 4);
  // Half way through the forward sweep the rotor slips back one electrical turn and stays.
  const std::int64_t slip = m.counts_per_turn / m.pole_pairs;
  for (std::size_t i = 3000; i < samples.size(); ++i) samples[i].encoder_count -= slip;
  const auto r = analyse(samples, counts());
  EXPECT_TRUE(r.has(ProblemKind::MoveDisagreesWithCommand) ||
              r.has(ProblemKind::InconsistentCountsPerElectricalTurn))
      << problems_text(r);
  EXPECT_FALSE(r.encoder_offset_counts);
}

TEST(Defects, WrongCountsPerTurnIsReportedNotRounded) {
  const SyntheticMotor m = motor();
  const auto samples = synthetic_sweep(m, plan(), 5);
  const auto not_whole = analyse(samples, counts(4500));  // 1.5 pole pairs' worth
  EXPECT_TRUE(not_whole.has(ProblemKind::PolePairsNotInteger)) << problems_text(not_whole);
  EXPECT_FALSE(not_whole.pole_pairs);
  EXPECT_FALSE(not_whole.encoder_offset_counts);

  AnalysisOptions both = counts(3000);
  both.pole_pairs = 4;
  const auto mismatch = analyse(samples, both);
  EXPECT_TRUE(mismatch.has(ProblemKind::CountsPerTurnMismatch)) << problems_text(mismatch);
  EXPECT_FALSE(mismatch.encoder_offset_counts);
}

TEST(Defects, NoIndexLeavesTheOffsetOutAndSaysWhy) {
  SyntheticMotor m = motor();
  m.has_index = false;
  const auto r = analyse(synthetic_sweep(m, plan(), 6), counts());
  EXPECT_TRUE(r.has(ProblemKind::NoIndex)) << problems_text(r);
  EXPECT_FALSE(r.encoder_offset_counts);
  EXPECT_FALSE(r.index_electrical_angle_deg);
  ASSERT_TRUE(r.pole_pairs && r.hall.bldc_pattern);  // the rest is still found
  EXPECT_TRUE(wrong_values(r, m).empty());
}

TEST(Defects, AnIndexThatLatchesOffItsMarkIsInconsistent) {
  const SyntheticMotor m = motor();
  auto samples = synthetic_sweep(m, plan(), 13);
  // A spurious latch a third of a turn away from the real mark (noise on the index line).
  std::int64_t real = 0;
  for (const Sample& s : samples) {
    if (s.index_seen) real = s.latched_count;
  }
  samples[2500].index_seen = true;
  samples[2500].latched_count = real + m.counts_per_turn / 3;
  const auto r = analyse(samples, counts());
  EXPECT_TRUE(r.has(ProblemKind::IndexInconsistent)) << problems_text(r);
  EXPECT_FALSE(r.encoder_offset_counts);
}

TEST(Defects, NamesEachStuckSensorHighOrLow) {
  for (int sensor = 1; sensor <= 3; ++sensor) {
    for (bool high : {true, false}) {
      SyntheticMotor m = motor();
      m.stuck_sensor = sensor;
      m.stuck_high = high;
      const auto r = analyse(synthetic_sweep(m, plan(), 7), counts());
      SCOPED_TRACE("hall" + std::to_string(sensor) + (high ? " high" : " low"));
      ASSERT_EQ(r.hall.sensors.size(), 3u);
      EXPECT_EQ(r.hall.sensors[static_cast<std::size_t>(sensor - 1)].condition,
                high ? SensorCondition::StuckHigh : SensorCondition::StuckLow);
      EXPECT_TRUE(message_has(r, ProblemKind::HallStuck, "hall" + std::to_string(sensor)));
      EXPECT_TRUE(r.has(ProblemKind::FewerThanSixHallStates));
      EXPECT_FALSE(r.hall.sequence);
      EXPECT_TRUE(wrong_values(r, m).empty());
      EXPECT_TRUE(r.encoder_offset_counts) << "the encoder's findings do not need the Halls";
    }
  }
}

TEST(Defects, NoHallSensorsAtAll) {
  SyntheticMotor m = motor();
  auto samples = synthetic_sweep(m, plan(), 8);
  for (Sample& s : samples) s.hall_state = 7;  // three open inputs with pull-ups
  const auto r = analyse(samples, counts());
  EXPECT_TRUE(message_has(r, ProblemKind::HallStuck, "no Hall sensor changed")) << problems_text(r);
  AnalysisOptions without = counts();
  without.hall_sensors_expected = false;
  EXPECT_TRUE(analyse(samples, without).problems.empty());
}

TEST(Defects, NamesANoisySensorAndKeepsTheMapWhenItCan) {
  SyntheticMotor m = motor();
  m.noisy_sensor = 3;
  m.noise_probability = 0.02;
  const auto r = analyse(synthetic_sweep(m, plan(), 9), counts());
  ASSERT_EQ(r.hall.sensors.size(), 3u);
  EXPECT_EQ(r.hall.sensors[2].condition, SensorCondition::Noisy);
  EXPECT_EQ(r.hall.sensors[0].condition, SensorCondition::Ok);
  EXPECT_EQ(r.hall.sensors[1].condition, SensorCondition::Ok);
  EXPECT_TRUE(wrong_values(r, m).empty()) << problems_text(r);
  EXPECT_TRUE(r.hall.sequence) << problems_text(r);
}

TEST(Defects, AVeryNoisySensorShowsMoreThanSixStates) {
  SyntheticMotor m = motor();
  m.noisy_sensor = 1;
  m.noise_probability = 0.3;
  const auto r = analyse(synthetic_sweep(m, plan(), 10), counts());
  EXPECT_TRUE(r.has(ProblemKind::MoreThanSixHallStates)) << problems_text(r);
  EXPECT_EQ(r.hall.sensors[0].condition, SensorCondition::Noisy);
  EXPECT_FALSE(r.hall.sequence);
}

TEST(Defects, SweepTooShortOrTooFewSamples) {
  const SyntheticMotor m = motor();
  SweepPlan short_plan = plan();
  short_plan.sweep_turns = 1.2;
  EXPECT_TRUE(analyse(synthetic_sweep(m, short_plan, 11), counts()).has(ProblemKind::SweepTooShort));
  const std::vector<Sample> few(5);
  EXPECT_TRUE(analyse(few, counts()).has(ProblemKind::NotEnoughSamples));
}

TEST(Defects, WithNeitherPolesNorCountsAndOneIndexPassTheAnalysisAsks) {
  SyntheticMotor m = motor();
  m.index_mechanical_turns = 0.9;  // passed once each way by this sweep
  SweepPlan p = plan();
  p.sweep_turns = 3.5;
  const auto r = analyse(synthetic_sweep(m, p, 12), {});
  EXPECT_TRUE(r.has(ProblemKind::NeedPolePairsOrCounts)) << problems_text(r);
  EXPECT_FALSE(r.pole_pairs);
  EXPECT_TRUE(r.encoder_direction);
  EXPECT_TRUE(wrong_values(r, m).empty());
}

}  // namespace
