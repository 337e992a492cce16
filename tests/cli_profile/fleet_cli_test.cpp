// SPDX-License-Identifier: GPL-2.0-or-later
// i20 profile apply --target T1 --target T2 ...: every card on its own thread and link; one
// target failing never changes what happens on another; exit 0 only if all are verified.
#include <gtest/gtest.h>

#include <algorithm>

#include "cli_profile_util.hpp"

using namespace i20::test;

namespace {

class FleetCli : public ::testing::Test {
 protected:
  Result fleet(const std::vector<std::string>& targets, std::vector<std::string> extra = {}) {
    // In-process simulators on the same 120 V line as the pty ones (kLine120Bus); the
    // control line is refused when no target is a simulator.
    std::vector<std::string> args{"--no-user-params"};
    if (std::ranges::any_of(targets, [](const auto& t) { return t.rfind("sim", 0) == 0; }))
      args.insert(args.end(), {"--sim-control", "busv 160"});
    if (json_mode) args.push_back("--json");
    args.insert(args.end(),
                {"profile", "apply", shipped("line-120v.yaml"), "--backup-dir", dir.path().string()});
    for (const auto& t : targets) args.insert(args.end(), {"--target", t});
    args.insert(args.end(), extra.begin(), extra.end());
    return run("i20", args, {}, 180);
  }
  // NVBRAKEONV as an in-process simulator with this EEPROM image holds it.
  std::string brake_on_in(const std::string& image) {
    return run("i20", {"--no-user-params", "--sim", "--sim-eeprom", image, "get", "--raw", "NVBRAKEONV"}).out;
  }
  std::string image(const std::string& name) { return (dir / name).string(); }

  bool json_mode = true;
  TempDir dir;
};

}  // namespace

TEST_F(FleetCli, ThreeTargetsOneDeadTheOthersApplyAndVerify) {
  SimProcess dead({"--busv", "160", "--drop", "1"});  // executes everything, answers nothing
  const auto a = image("a.eeprom"), b = image("b.eeprom");
  auto r = fleet({"sim:" + a, dead.port(), "sim:" + b});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  auto j = json(r);
  EXPECT_EQ(j["exit_code"].as<int>(), 1);
  ASSERT_EQ(j["targets"].size(), 3u) << r.out;
  EXPECT_EQ(outcome(j["targets"][0]), "done");
  EXPECT_EQ(outcome(j["targets"][1]), "failed");
  EXPECT_EQ(outcome(j["targets"][2]), "done");
  EXPECT_EQ(j["targets"][1]["target"].as<std::string>(), dead.port());
  EXPECT_EQ(brake_on_in(a), "NVBRAKEONV = 19000\n");
  EXPECT_EQ(brake_on_in(b), "NVBRAKEONV = 19000\n");
  EXPECT_EQ(data_writes(dead.trace()), 0u) << "a card that never answered got no write";
  EXPECT_EQ(dead.control("drop 0"), "ok");
  EXPECT_EQ(sim_value(dead, "NVBRAKEONV"), 36000);

  json_mode = false;
  r = fleet({"sim:" + a, dead.port(), "sim:" + b});
  EXPECT_EQ(r.exit_code, 0) << "the dead card answers again now: " << r.out << r.err;
  EXPECT_NE(r.out.find("TARGET"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("nothing-to-do"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 of 3 targets applied and verified (or had nothing to do); 0 did not"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.err.find("\033["), std::string::npos) << "no progress redraws when stderr is not a terminal";
}

TEST_F(FleetCli, ARolledBackTargetDoesNotChangeTheOthers) {
  SimProcess good{kLine120Bus}, failing{kLine120Bus};
  ASSERT_EQ(failing.control("eeprom-power-loss torn"), "ok");
  const auto r = fleet({good.port(), failing.port(), "sim:" + image("c.eeprom")});
  EXPECT_EQ(r.exit_code, 4) << "a card needing attention outranks everything: " << r.out << r.err;
  const auto j = json(r);
  ASSERT_EQ(j["targets"].size(), 3u);
  EXPECT_EQ(outcome(j["targets"][0]), "done");
  EXPECT_EQ(outcome(j["targets"][1]), "uncertain");
  EXPECT_EQ(outcome(j["targets"][2]), "done");
  expect_report_matches_card(
      j["targets"][0], [&](const std::string& c) { return sim_value(good, c); }, "good");
  EXPECT_EQ(brake_on_in(image("c.eeprom")), "NVBRAKEONV = 19000\n");
  EXPECT_EQ(eeprom_writes(good.trace()), 6u);
  std::set<std::string> backups;
  for (const auto& t : j["targets"]) backups.insert(t["backup"].as<std::string>());
  EXPECT_EQ(backups.size(), 3u) << "one backup per card, none overwritten";
}

TEST_F(FleetCli, ReapplyingToAVerifiedFleetWritesNothing) {
  SimProcess one{kLine120Bus}, two{kLine120Bus};
  auto r = fleet({one.port(), two.port()});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto writes_one = eeprom_writes(one.trace()), writes_two = eeprom_writes(two.trace());
  EXPECT_EQ(writes_one, 6u);
  EXPECT_EQ(writes_two, 6u);
  r = fleet({one.port(), two.port()});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = json(r);
  for (const auto& t : j["targets"]) EXPECT_EQ(outcome(t), "nothing-to-do");
  EXPECT_EQ(eeprom_writes(one.trace()), writes_one);
  EXPECT_EQ(eeprom_writes(two.trace()), writes_two);
}

TEST_F(FleetCli, AMissingPortIsNotReachedWhileTheOthersApply) {
  const auto r = fleet({"/dev/i20-no-such-port", "sim:" + image("d.eeprom")});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  const auto j = json(r);
  EXPECT_EQ(outcome(j["targets"][0]), "failed");
  EXPECT_NE(j["targets"][0]["error"].as<std::string>().find("i20-no-such-port"), std::string::npos);
  EXPECT_EQ(outcome(j["targets"][1]), "done");
}

TEST_F(FleetCli, DryRunPlansEveryTargetAndWritesNothing) {
  SimProcess one{kLine120Bus};
  const auto r = fleet({one.port(), "sim"}, {"--dry-run"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = json(r);
  for (const auto& t : j["targets"]) {
    EXPECT_EQ(outcome(t), "dry-run");
    EXPECT_EQ(t["plan"]["steps"].size(), 6u);
  }
  EXPECT_EQ(data_writes(one.trace()), 0u);
  EXPECT_TRUE(backups_in(dir.path()).empty());
}

TEST_F(FleetCli, BadTargetListsAreRefusedBeforeAnythingStarts) {
  json_mode = false;
  const auto x = "sim:" + image("x.eeprom");
  auto r = fleet({x, x});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("given twice"), std::string::npos) << r.err;
  EXPECT_EQ(fleet({"eth://"}).exit_code, 2);
  r = fleet({"tcp://10.0.0.1"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("sim:FILE"), std::string::npos) << "lists the forms: " << r.err;
  r = run("i20", {"--sim", "profile", "apply", shipped("line-120v.yaml"), "--target", "sim"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_FALSE(std::filesystem::exists(image("x.eeprom"))) << "no simulator was even started";
}
