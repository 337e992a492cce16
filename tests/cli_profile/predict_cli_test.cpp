// SPDX-License-Identifier: GPL-2.0-or-later
// What the tool predicts is what it does: `profile validate` against a card runs apply's own
// checks (the transaction's dry run), a fleet dry run names what it would write, a fleet
// reset shows in the table, `profile diff` exits as diff(1) over many targets, "not live
// yet" counts every pending NV value, `--sim-control` is refused where it cannot act, and
// `profile undo` puts a backup back through apply's transaction. Judged on the card (the
// simulator's values, trace and EEPROM image), not on the tool's word alone.
#include <gtest/gtest.h>

#include <set>

#include "cli_profile_util.hpp"

using namespace i20::test;

namespace {

class PredictCli : public ::testing::Test {
 protected:
  std::string image(const std::string& name) { return (dir / name).string(); }
  // `i20 --no-user-params ARGS` (the in-process simulator, sim: targets).
  Result i20(std::vector<std::string> args) {
    args.insert(args.begin(), "--no-user-params");
    return run("i20", args, {}, 180);
  }
  // The EEPROM image of an in-process simulator card after a first read created it.
  std::string fresh_image(const std::string& name) {
    const auto file = image(name);
    EXPECT_EQ(i20({"--sim", "--sim-eeprom", file, "get", "NVBRAKEONV"}).exit_code, 0);
    return file;
  }
  std::set<std::string> rules_of(const YAML::Node& findings) {
    std::set<std::string> rules;
    for (const auto& f : findings) rules.insert(f["rule"].as<std::string>());
    return rules;
  }

  TempDir dir;
};

}  // namespace

// The reproduction: on the simulator's 320 V bus line-120v's 190 V brake-on and
// 195 V over-voltage are refused by apply; validate against the same card says so, with
// the same findings and the same exit code, and neither writes anything.
TEST_F(PredictCli, ValidateAgainstACardJudgesWhatApplyJudges) {
  const auto card = fresh_image("card.eeprom");
  const auto before = slurp_file(card);
  const auto validate = i20({"--sim", "--sim-eeprom", card, "profile", "validate", "line-120v"});
  EXPECT_EQ(validate.exit_code, 3) << validate.out << validate.err;
  EXPECT_NE(validate.out.find("[bus-measured-brake]"), std::string::npos) << validate.out;
  EXPECT_NE(validate.out.find("INVALID"), std::string::npos) << validate.out;
  EXPECT_EQ(validate.out.find(": valid"), std::string::npos) << validate.out;
  const auto apply = i20(
      {"--sim", "--sim-eeprom", card, "profile", "apply", "line-120v", "--backup-dir", dir.path().string()});
  EXPECT_EQ(apply.exit_code, validate.exit_code) << apply.out << apply.err;

  const auto v = json(i20({"--json", "--sim", "--sim-eeprom", card, "profile", "validate", "line-120v"}));
  const auto a =
      json(i20({"--json", "--sim", "--sim-eeprom", card, "profile", "apply", "line-120v", "--dry-run"}));
  EXPECT_FALSE(v["valid"].as<bool>());
  EXPECT_EQ(v["exit_code"].as<int>(), a["exit_code"].as<int>());
  EXPECT_EQ(rules_of(v["files"][0]["findings"]), rules_of(a["findings"]))
      << "the same rules, the same findings";
  EXPECT_EQ(slurp_file(card), before) << "validate and a refused apply leave the EEPROM as it was";
  EXPECT_TRUE(backups_in(dir.path()).empty());

  // On a 120 V line (160 V of bus) both go ahead.
  const auto ok =
      i20({"--sim", "--sim-eeprom", card, "--sim-control", "busv 160", "profile", "validate", "line-120v"});
  EXPECT_EQ(ok.exit_code, 0) << ok.out << ok.err;
  EXPECT_NE(ok.out.find(": valid ("), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("checked against 8I20"), std::string::npos) << ok.out;
  EXPECT_EQ(slurp_file(card), before);
}

TEST_F(PredictCli, ValidateWithoutACardSaysWhichRulesItCouldNotJudge) {
  const auto r = i20({"profile", "validate", "line-120v"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("without a card"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bus-measured-"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("were not judged"), std::string::npos) << r.out;
  const auto j = json(i20({"--json", "profile", "validate", "line-120v"}));
  EXPECT_NE(j["not_judged"].as<std::string>().find("measured-bus"), std::string::npos);
}

// A rule error is a refusal (exit 3) with or without a card; a file that cannot be read is
// bad input (2).
TEST_F(PredictCli, ValidateExitCodesAreApplysExitCodes) {
  const auto bad = write_file(dir / "bad.yaml", "name: bad\nparameters:\n  NVMAXCURRENT: 45 A\n");
  auto r = i20({"profile", "validate", bad});
  EXPECT_EQ(r.exit_code, 3) << r.out;
  const auto card = fresh_image("card.eeprom");
  r = i20({"--sim", "--sim-eeprom", card, "profile", "validate", bad});
  EXPECT_EQ(r.exit_code, 3) << r.out;
  EXPECT_NE(r.out.find("[range]"), std::string::npos) << r.out;
  r = i20({"--sim", "--sim-eeprom", card, "profile", "apply", bad});
  EXPECT_EQ(r.exit_code, 3) << r.err;
  const auto broken = write_file(dir / "broken.yaml", "name: [\n");
  EXPECT_EQ(i20({"profile", "validate", broken}).exit_code, 2);
  EXPECT_EQ(i20({"--sim", "--sim-eeprom", card, "profile", "validate", broken}).exit_code, 2);
}

// Two cards: one on a 320 V bus (refused), one on a 120 V line (valid). Each is judged on
// its own, nothing is written on either.
TEST_F(PredictCli, ValidateOverManyTargetsJudgesEachCard) {
  SimProcess high;  // 320 V bus
  const auto low = fresh_image("low.eeprom");
  const auto before = slurp_file(low);
  const auto r = i20({"--sim-control", "busv 160", "profile", "validate", "line-120v", "--target",
                      high.port(), "--target", "sim:" + low});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("== " + high.port()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("== sim:" + low), std::string::npos) << r.out;
  const auto j = json(i20({"--json", "--sim-control", "busv 160", "profile", "validate", "line-120v",
                           "--target", high.port(), "--target", "sim:" + low}));
  const auto targets = j["files"][0]["targets"];
  ASSERT_EQ(targets.size(), 2u) << r.out;
  EXPECT_FALSE(targets[0]["valid"].as<bool>());
  EXPECT_EQ(targets[0]["exit_code"].as<int>(), 3);
  EXPECT_TRUE(targets[1]["valid"].as<bool>());
  EXPECT_EQ(high.writes_seen(), 0u);
  EXPECT_EQ(slurp_file(low), before);
}

TEST_F(PredictCli, FleetDryRunSaysWhatItWouldWrite) {
  SimProcess one{kLine120Bus};
  const auto two = fresh_image("two.eeprom");
  const auto before = slurp_file(two);
  const auto r = i20({"--sim-control", "busv 160", "profile", "apply", "line-120v", "--dry-run",
                      "--backup-dir", dir.path().string(), "--target", one.port(), "--target", "sim:" + two});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("WOULD WRITE"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("NVBRAKEOFFV, NVBRAKEONV"), std::string::npos) << "names the cells: " << r.out;
  EXPECT_NE(r.out.find("DRY RUN: would write 12 cells on 2 of 2 targets; nothing was written"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("applied and verified"), std::string::npos) << r.out;
  EXPECT_EQ(one.writes_seen(), 0u);
  EXPECT_EQ(slurp_file(two), before);
  EXPECT_TRUE(backups_in(dir.path()).empty());
}

TEST_F(PredictCli, FleetResetShowsInTheTable) {
  SimProcess one{kLine120Bus};
  const auto two = image("two.eeprom");
  auto r = i20({"--sim-control", "busv 160", "profile", "apply", "line-120v", "--reset", "--yes",
                "--backup-dir", dir.path().string(), "--target", one.port(), "--target", "sim:" + two});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("RESET"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  done  "), std::string::npos) << r.out;
  EXPECT_EQ(sim_value(one, "BRAKEONV"), 19000) << "the reset made the EEPROM value live";
  // Nothing to write and nothing pending: the table says the reset was not needed.
  r = i20({"--sim-control", "busv 160", "profile", "apply", "line-120v", "--reset", "--yes", "--backup-dir",
           dir.path().string(), "--target", one.port(), "--target", "sim:" + two});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("not needed"), std::string::npos) << r.out;
  r = i20({"--sim-control", "busv 160", "profile", "apply", "line-120v", "--reset", "--dry-run", "--target",
           one.port(), "--target", "sim:" + image("three.eeprom")});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("would reset"), std::string::npos) << r.out;
}

// diff(1)'s codes: 0 identical, 1 values differ, 2 trouble; several targets, one section each.
TEST_F(PredictCli, DiffExitsAsDiffAndTakesManyTargets) {
  SimProcess one{kLine120Bus};
  auto r = i20_on(one.port(), {"profile", "diff", "line-120v"});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("6 of 6 values differ"), std::string::npos) << r.out;
  r = i20_on(one.port(), {"profile", "diff", "defaults"});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(i20_on(one.port(), {"profile", "diff", (dir / "none.yaml").string()}).exit_code, 2);

  const auto other = image("other.eeprom");
  r = i20({"profile", "diff", "line-120v", "--target", one.port(), "--target", "sim:" + other});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("== " + one.port()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("== sim:" + other), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0 of 2 targets hold every value; 2 differ; 0 could not be compared"),
            std::string::npos)
      << r.out;

  ASSERT_EQ(
      i20_on(one.port(), {"profile", "apply", "line-120v", "--backup-dir", dir.path().string()}).exit_code,
      0);
  r = i20({"profile", "diff", "line-120v", "--target", one.port()});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = json(i20({"--json", "profile", "diff", "line-120v", "--target", one.port(), "--target",
                           "sim:" + other, "--target", "/dev/i20-no-such-port"}));
  EXPECT_EQ(j["exit_code"].as<int>(), 2) << "a card not reached is trouble";
  ASSERT_EQ(j["targets"].size(), 3u);
  EXPECT_EQ(j["targets"][0]["exit_code"].as<int>(), 0);
  EXPECT_EQ(j["targets"][1]["exit_code"].as<int>(), 1);
  EXPECT_EQ(j["targets"][1]["differ"].as<int>(), 6);
  EXPECT_EQ(j["targets"][2]["exit_code"].as<int>(), 2);
  const auto writes = one.writes_seen();
  EXPECT_EQ(i20({"profile", "diff", "line-120v", "--target", one.port()}).exit_code, 0);
  EXPECT_EQ(one.writes_seen(), writes) << "diff only reads";
}

// Every pending NV value counts, not only the ones this command wrote.
TEST_F(PredictCli, NotLiveYetCountsEveryPendingValueOnTheCard) {
  SimProcess card{kLine120Bus};
  auto r = i20_on(card.port(), {"set", "NVBRAKEOFFV=170V", "NVBRAKEONV=190V"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("not live yet: 2 of them"), std::string::npos) << r.out;
  r = i20_on(card.port(), {"set", "NVMAXCURRENT=11A"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("not live yet: 3 of them"), std::string::npos)
      << "the first set's two count too: " << r.out;
  const auto j = json(i20_on(card.port(), {"--json", "set", "NVMAXCURRENT=11A"}));
  EXPECT_EQ(j["not_live"].size(), 3u) << "nothing to do, still three pending";
}

// The simulator's control lines cannot reach a real card: refused before any byte is sent.
TEST_F(PredictCli, SimControlWithARealTargetIsBadInput) {
  SimProcess card;
  auto r = run("i20", {"--port", card.port(), "--sim-control", "busv 160", "get", "BUSV"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--sim-control"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  r = run("i20", {"--eth", "127.0.0.1", "--sim-control", "busv 160", "get", "BUSV"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  r = i20({"--sim-control", "busv 160", "profile", "apply", "line-120v", "--target", card.port()});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--sim-control"), std::string::npos) << r.err;
  EXPECT_EQ(
      i20({"--sim-control", "busv 160", "profile", "diff", "line-120v", "--target", card.port()}).exit_code,
      2);
  EXPECT_EQ(card.commands_seen(), 0u) << "nothing was sent: " << card.trace();
}

// undo: the backup apply wrote goes back through the same transaction (plan first, verify),
// and the values it replaces are backed up in turn, so --last twice is a redo.
TEST_F(PredictCli, UndoPutsTheBackupBackThroughTheTransaction) {
  SimProcess card{kLine120Bus};
  const auto backups = dir.path().string();
  ASSERT_EQ(i20_on(card.port(), {"profile", "apply", "line-120v", "--backup-dir", backups}).exit_code, 0);
  ASSERT_EQ(sim_value(card, "NVBRAKEONV"), 19000);
  const auto saved = backups_in(dir.path());
  ASSERT_EQ(saved.size(), 1u);

  auto r =
      i20_on(card.port(), {"profile", "undo", saved.front().string(), "--dry-run", "--backup-dir", backups});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Plan: 6 writes"), std::string::npos) << "the diff first: " << r.out;
  EXPECT_NE(r.out.find("360.00 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("DRY RUN"), std::string::npos) << r.out;
  EXPECT_EQ(sim_value(card, "NVBRAKEONV"), 19000) << "a dry run writes nothing";

  const auto writes = eeprom_writes(card.trace());
  r = i20_on(card.port(), {"profile", "undo", "--last", "--backup-dir", backups});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find(saved.front().string()), std::string::npos) << "names the backup: " << r.out;
  EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 6 values written"), std::string::npos) << r.out;
  EXPECT_EQ(eeprom_writes(card.trace()), writes + 6);
  EXPECT_EQ(sim_value(card, "NVBRAKEONV"), 36000);
  EXPECT_EQ(sim_value(card, "NVBRAKEOFFV"), 34000);
  ASSERT_EQ(backups_in(dir.path()).size(), 2u) << "the undone values are backed up too";

  r = i20_on(card.port(), {"profile", "undo", "--last", "--backup-dir", backups});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(sim_value(card, "NVBRAKEONV"), 19000) << "the newest backup now is the one the undo took";
}

TEST_F(PredictCli, UndoRefusesBadRequestsBeforeWriting) {
  SimProcess card{kLine120Bus};
  EXPECT_EQ(i20_on(card.port(), {"profile", "undo"}).exit_code, 2);
  auto r = i20_on(card.port(), {"profile", "undo", "--last", "--backup-dir", (dir / "empty").string()});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("no backup of unit"), std::string::npos) << r.err;
  EXPECT_EQ(i20_on(card.port(), {"profile", "undo", (dir / "missing.yaml").string()}).exit_code, 2);
  // A backup whose values the rules refuse on this card (a 190 V brake-on on a 320 V bus).
  SimProcess high;
  ASSERT_EQ(
      i20_on(card.port(), {"profile", "apply", "line-120v", "--backup-dir", dir.path().string()}).exit_code,
      0);
  const auto undo_file = write_file(dir / "low.yaml", slurp_file(shipped("line-120v.yaml")));
  r = i20_on(high.port(), {"profile", "undo", undo_file, "--backup-dir", dir.path().string()});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_EQ(high.writes_seen(), 0u);
}
