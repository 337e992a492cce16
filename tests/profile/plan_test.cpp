// SPDX-License-Identifier: GPL-2.0-or-later
// Diff and plan: only what differs is written, in an order that is safe at every step.
#include "profile/plan.hpp"

#include <gtest/gtest.h>

#include <random>

#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

namespace {

std::vector<std::string> order_of(const Plan& plan) {
  std::vector<std::string> cells;
  for (const auto& s : plan.steps) cells.push_back(s.cell);
  return cells;
}

}  // namespace

TEST(ProfileDiff, ShowsBothSidesInEngineeringUnitsAndRaw) {
  const Profile p = load(with_params("  NVBRAKEONV: 190 V\n  NVKQP: 50\n  NVMAXCURRENT: 7.5 A\n"));
  const RawValues card{{"NVBRAKEONV", 36000}, {"NVKQP", 50}};
  const auto rows = diff(p, db(), card);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].cell, "NVBRAKEONV");
  EXPECT_TRUE(rows[0].nv);
  EXPECT_EQ(rows[0].profile_raw, 19000);
  EXPECT_EQ(rows[0].profile_text, "190.00 V");
  EXPECT_EQ(rows[0].card_raw, 36000);
  EXPECT_EQ(rows[0].card_text, "360.00 V");
  EXPECT_FALSE(rows[0].equal);
  EXPECT_EQ(rows[0].where, "test.yaml:3");
  EXPECT_TRUE(rows[1].equal);
  EXPECT_EQ(rows[1].card_text, "50");
  EXPECT_FALSE(rows[2].card_raw);  // not read: unknown, so it counts as different
  EXPECT_EQ(rows[2].card_text, "?");
  EXPECT_FALSE(rows[2].equal);
}

TEST(ProfilePlan, WritesOnlyWhatDiffers) {
  const Profile p = load(with_params("  NVKQP: 60\n  NVKDP: 60\n  NVKQI: 150000\n"));
  const RawValues card{{"NVKQP", 50}, {"NVKDP", 60}, {"NVKQI", 150000}};
  const Plan plan = make_plan(p, db(), card);
  EXPECT_EQ(order_of(plan), std::vector<std::string>{"NVKQP"});
  EXPECT_EQ(plan.unchanged.size(), 2u);
  EXPECT_TRUE(plan.reset_needed);
  const RawValues same{{"NVKQP", 60}, {"NVKDP", 60}, {"NVKQI", 150000}};
  EXPECT_TRUE(make_plan(p, db(), same).empty());
  EXPECT_FALSE(make_plan(p, db(), same).reset_needed);
}

TEST(ProfilePlan, ResetOnlyForEepromChanges) {
  const Profile p = load(with_params("  KQP: 60\n"));
  const Plan plan = make_plan(p, db(), {{"KQP", 50}});
  EXPECT_EQ(plan.steps.size(), 1u);
  EXPECT_FALSE(plan.reset_needed);
}

// The manual's 120 V example from the 240 V defaults: lowering both, BRAKEOFFV goes first
// so that BRAKEOFFV < BRAKEONV holds after every single write.
TEST(ProfilePlan, LoweringTheBrakeWritesOffFirst) {
  const Profile p = load(with_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 170 V\n"));
  const Plan plan = make_plan(p, db(), {{"NVBRAKEONV", 36000}, {"NVBRAKEOFFV", 34000}});
  EXPECT_EQ(order_of(plan), (std::vector<std::string>{"NVBRAKEOFFV", "NVBRAKEONV"}));
}

TEST(ProfilePlan, RaisingTheBrakeWritesOnFirst) {
  const Profile p = load(with_params("  NVBRAKEOFFV: 340 V\n  NVBRAKEONV: 360 V\n"));
  const Plan plan = make_plan(p, db(), {{"NVBRAKEONV", 19000}, {"NVBRAKEOFFV", 17000}});
  EXPECT_EQ(order_of(plan), (std::vector<std::string>{"NVBRAKEONV", "NVBRAKEOFFV"}));
}

TEST(ProfilePlan, EepromBeforeWorkingAndCurrentLimitLowerFirstRaiseLast) {
  const Profile p = load(with_params(
      "  KQP: 60\n  NVMAXCURRENT: 12 A\n  NVKQP: 60\n  MAXCURRENT: 5 A\n  NVDEADZONE: 3\n  NVKDP: 40\n"));
  const RawValues card{{"KQP", 50},          {"NVMAXCURRENT", 1000}, {"NVKQP", 50},
                       {"MAXCURRENT", 1000}, {"NVDEADZONE", 0},      {"NVKDP", 50}};
  EXPECT_EQ(order_of(make_plan(p, db(), card)),
            (std::vector<std::string>{"NVKDP", "NVKQP", "NVDEADZONE", "NVMAXCURRENT", "MAXCURRENT", "KQP"}));
}

TEST(ProfilePlan, BothWritesTheEepromHalfFirst) {
  const Profile p = load(with_params("  BRAKEONV: {value: 300 V, target: both}\n"));
  EXPECT_EQ(order_of(make_plan(p, db(), {})), (std::vector<std::string>{"NVBRAKEONV", "BRAKEONV"}));
}

// Property: for random valid before/after threshold sets, every intermediate state of the
// planned order keeps BUSUNDERV < BRAKEOFFV < BRAKEONV < BUSOVERV.
TEST(ProfilePlan, VoltageThresholdsStayOrderedAtEveryStep) {
  const std::vector<std::string> chain{"NVBUSUNDERV", "NVBRAKEOFFV", "NVBRAKEONV", "NVBUSOVERV"};
  std::mt19937 rng(8120);
  std::uniform_int_distribution<int> volts(20, 385);
  const auto sorted_set = [&] {
    std::vector<int> v;
    while (v.size() < 4) {
      const int x = volts(rng);
      if (std::ranges::find(v, x) == v.end()) v.push_back(x);
    }
    std::ranges::sort(v);
    return v;
  };
  for (int trial = 0; trial < 500; ++trial) {
    const auto before = sorted_set();
    const auto after = sorted_set();
    std::string lines;
    RawValues card;
    for (std::size_t i = 0; i < chain.size(); ++i) {
      lines += "  " + chain[i] + ": " + std::to_string(after[i]) + " V\n";
      card[chain[i]] = before[i] * 100;
    }
    const Plan plan = make_plan(load(with_params(lines)), db(), card);
    RawValues state = card;
    for (const auto& step : plan.steps) {
      state[step.cell] = step.profile_raw;
      for (std::size_t i = 1; i < chain.size(); ++i)
        ASSERT_LT(state[chain[i - 1]], state[chain[i]])
            << "trial " << trial << " after writing " << step.cell;
    }
  }
}
