// SPDX-License-Identifier: GPL-2.0-or-later
// ProfileApply, the profile commands' use case (profile apply, undo, validate against cards,
// a fleet): refused before any card is asked, one job for the dry run and the write, and
// one card or several through the same judged job. Judged by the simulator's memory and by
// the card's own answers afterwards, not by what the run reports.
#include "ops/profile_apply.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <mutex>

#include "device/errors.hpp"
#include "sim_rig.hpp"
#include "test_util.hpp"

using namespace i20::ops;
using namespace i20::ops::testing;
using namespace i20::profile::testing;
namespace fs = std::filesystem;

namespace {

const std::string kBrake = with_params("  NVBRAKEOFFV: 170 V\n  NVBRAKEONV: 190 V\n");

std::vector<std::string> planned_cells(const i20::profile::Plan& plan) {
  std::vector<std::string> cells;
  for (const auto& step : plan.steps) cells.push_back(step.cell);
  return cells;
}

}  // namespace

TEST(ProfileApplyUseCase, AValuePastTheCardsFixedLimitIsRefusedWhenMadeWithNothingAsked) {
  SimRig rig(RigOptions().bus(160));
  auto amp = rig.open();
  const auto before = rig.stats();
  // Above the fixed 385 V brake-on that protects the module (no overlay can widen it).
  const auto past_limit = load(with_params("  NVBRAKEOFFV: 370 V\n  NVBRAKEONV: 390 V\n"), amp->db());
  EXPECT_THROW(ProfileApply({.profile = &past_limit, .db = &amp->db()}), i20::device::SafetyError);
  EXPECT_EQ(rig.stats().commands_executed, before.commands_executed)
      << "the refusal asked the card something";
}

TEST(ProfileApplyUseCase, TheDryRunPlansWhatTheWriteThenDoesAndWritesNothing) {
  SimRig rig(RigOptions().bus(160));
  auto amp = rig.open();
  const auto profile = load(kBrake, amp->db());
  std::vector<std::string> predicted;
  const auto before = rig.truth();
  const ProfileApply dry({.profile = &profile, .db = &amp->db(), .dry_run = true});
  auto run = dry.run_on(*amp, {}, [&](const i20::profile::Plan& p) { predicted = planned_cells(p); });
  ASSERT_EQ(run.outcome, Outcome::DryRun) << (run.result ? run.result->reason : run.error);
  auto cells = predicted;
  std::ranges::sort(cells);
  EXPECT_EQ(cells, (std::vector<std::string>{"NVBRAKEOFFV", "NVBRAKEONV"}));
  EXPECT_TRUE(rig.unexplained_changes(before, rig.truth(), {}).empty()) << "the dry run wrote";

  std::vector<std::string> planned;
  std::vector<std::string> activity;
  const ProfileApply write({.profile = &profile, .db = &amp->db()});
  run = write.run_on(
      *amp, [&](const std::string& what) { activity.push_back(what); },
      [&](const i20::profile::Plan& p) { planned = planned_cells(p); });
  ASSERT_EQ(run.outcome, Outcome::Done) << (run.result ? run.result->reason : run.error);
  EXPECT_EQ(planned, predicted) << "the write ran another plan than the dry run showed";
  EXPECT_FALSE(activity.empty()) << "the writes were not told as they happened";
  // The card itself now holds the profile: the same dry run plans nothing.
  run = dry.run_on(*amp);
  ASSERT_TRUE(run.result) << run.error;
  EXPECT_TRUE(run.result->plan.empty()) << planned_cells(run.result->plan).front();
}

TEST(ProfileApplyUseCase, SeveralTargetsRunAsAFleetEachToldByItsIndex) {
  const auto dir = fs::temp_directory_path() / ("i20-profile-apply-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<Endpoint> targets{parse_endpoint("sim:" + (dir / "a.eeprom").string(), 0),
                                      parse_endpoint("sim:" + (dir / "b.eeprom").string(), 1)};
  const auto profile = load(with_params("  NVMAXCURRENT: 11 A\n"));  // the simulator's bus is 320 V
  std::mutex told_lock;
  std::map<std::size_t, std::size_t> told;  // index -> activity lines
  const ProfileApply write({.profile = &profile, .db = &db()});
  const auto runs = write.run_on(targets, [&](std::size_t index, const std::string&) {
    const std::lock_guard lock(told_lock);
    ++told[index];
  });
  ASSERT_EQ(runs.size(), 2u);
  for (const auto& run : runs)
    EXPECT_EQ(run.outcome, Outcome::Done)
        << run.target.text << ": " << run.error << (run.result ? run.result->reason : "");
  EXPECT_EQ(told.size(), 2u) << "a target's activity was not told under its index";
  // Each card's EEPROM (its file) holds the profile: a dry run of the same profile plans nothing.
  const ProfileApply dry({.profile = &profile, .db = &db(), .dry_run = true});
  for (const auto& run : dry.run_on(targets)) {
    ASSERT_TRUE(run.result) << run.target.text << ": " << run.error;
    EXPECT_TRUE(run.result->plan.empty()) << run.target.text << ": the card does not hold the profile";
  }
  fs::remove_all(dir);
}
