// SPDX-License-Identifier: GPL-2.0-or-later
// i20 profile validate | diff | apply | save as processes against i20sim --pty.
#include <gtest/gtest.h>

#include "cli_profile_util.hpp"

using namespace i20::test;

namespace {

class ProfileCli : public ::testing::Test {
 protected:
  Result i20(const std::vector<std::string>& args) { return i20_on(sim.port(), args); }
  // apply with the backup going to the test's own directory.
  Result apply(std::vector<std::string> args) {
    args.insert(args.begin(), {"profile", "apply"});
    args.insert(args.end(), {"--backup-dir", dir.path().string()});
    return i20(args);
  }
  std::int64_t card(const std::string& name) { return sim_value(sim, name); }

  SimProcess sim{kLine120Bus};
  TempDir dir;
};

// NVBRAKEONV 360 V -> 190 V needs the brake-off voltage below it: on a factory card
// (NVBRAKEOFFV 340 V) this profile breaks the manual's brake order, on a card already set
// to 170 V it does not.
const char* kBrakeOnly =
    "name: brake-on-only\n"
    "parameters:\n"
    "  NVBRAKEONV: 190 V\n";

}  // namespace

TEST_F(ProfileCli, ShippedProfilesValidateWithoutFindings) {
  std::vector<std::string> args{"profile", "validate"};
  for (const auto& entry : std::filesystem::directory_iterator(source_dir() / "profiles"))
    if (entry.path().extension() == ".yaml") args.push_back(entry.path().string());
  ASSERT_GE(args.size(), 8u);
  const auto r = run("i20", args);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  for (std::size_t i = 2; i < args.size(); ++i)
    EXPECT_NE(r.out.find(args[i] + ": valid (no findings)"), std::string::npos) << r.out;
}

TEST_F(ProfileCli, ValidateNamesFileLineKeyAndRule) {
  const auto bad = write_file(dir / "bad.yaml",
                              "name: bad\n"
                              "parameters:\n"
                              "  NVBRAKEONV: 300 V\n"
                              "  NVBRAKEOFFV: 320 V\n"
                              "  NVMAXCURRENT: 45 A\n");
  auto r = run("i20", {"profile", "validate", bad});
  EXPECT_EQ(r.exit_code, 3) << "apply would refuse it: " << r.out << r.err;
  EXPECT_NE(r.out.find(bad + ":4: error: NVBRAKEOFFV: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("[brake-order]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(bad + ":5: error: NVMAXCURRENT: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(bad + ": INVALID"), std::string::npos) << r.out;

  const auto typo = write_file(dir / "typo.yaml", "name: typo\nparameters:\n  NVBRAKONV: 190 V\n");
  r = run("i20", {"profile", "validate", typo});
  EXPECT_EQ(r.exit_code, 2) << "a file that cannot be loaded is bad input";
  EXPECT_NE(r.out.find(typo + ":3: error: NVBRAKONV: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("NVBRAKEONV"), std::string::npos) << "suggests the right name: " << r.out;
  EXPECT_NE(r.out.find("[unknown-parameter]"), std::string::npos) << r.out;

  const auto j = json(run("i20", {"--json", "profile", "validate", bad, typo}));
  EXPECT_FALSE(j["valid"].as<bool>());
  ASSERT_EQ(j["files"].size(), 2u);
  std::map<std::string, std::string> where_of_rule;
  for (const auto& f : j["files"][0]["findings"])
    where_of_rule[f["rule"].as<std::string>()] = f["where"].as<std::string>();
  EXPECT_EQ(where_of_rule["brake-order"], bad + ":4");
  EXPECT_EQ(where_of_rule["range"], bad + ":5");
  EXPECT_EQ(j["files"][1]["findings"][0]["rule"].as<std::string>(), "unknown-parameter");
}

TEST_F(ProfileCli, ValidateWithACardJudgesAgainstTheCardsValues) {
  const auto file = write_file(dir / "brake.yaml", kBrakeOnly);
  auto r = run("i20", {"profile", "validate", file});
  EXPECT_EQ(r.exit_code, 3) << "factory NVBRAKEOFFV 340 V is above 190 V: " << r.out;
  EXPECT_NE(r.out.find("[brake-order]"), std::string::npos) << r.out;
  ASSERT_EQ(i20({"set", "NVBRAKEOFFV=170V"}).exit_code, 0);
  const auto before = data_writes(sim.trace());
  r = i20({"profile", "validate", file});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("valid (no findings, checked against 8I20 unit 0x00012345"), std::string::npos)
      << r.out;
  EXPECT_EQ(data_writes(sim.trace()), before) << "validate only reads";
}

TEST_F(ProfileCli, DiffListsEveryParameterInEngineeringUnits) {
  const auto r = i20({"profile", "diff", shipped("line-120v.yaml")});
  ASSERT_EQ(r.exit_code, 1) << "values differ, as diff(1): " << r.err;
  EXPECT_NE(r.out.find("NVBRAKEONV"), std::string::npos);
  EXPECT_NE(r.out.find("190.00 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("360.00 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("6 of 6 values differ"), std::string::npos) << r.out;
  const auto j = json(i20({"--json", "profile", "diff", shipped("defaults.yaml")}));
  EXPECT_EQ(j["differ"].as<int>(), 0) << "a factory card holds the defaults";
  EXPECT_EQ(j["rows"].size(), 8u);
  EXPECT_EQ(j["rows"][0]["card_raw"].as<std::int64_t>(), j["rows"][0]["profile_raw"].as<std::int64_t>());
}

TEST_F(ProfileCli, DryRunPrintsThePlanAndWritesNothing) {
  const auto before = sim.trace();
  const auto r = apply({shipped("line-120v.yaml"), "--dry-run"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Plan: 6 writes"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("DRY RUN: 6 values would be written, 0 already set; nothing was written"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(data_writes(sim.trace()), data_writes(before)) << "a dry run sends no write at all";
  EXPECT_TRUE(backups_in(dir.path()).empty()) << "and takes no backup";
  EXPECT_EQ(card("NVBRAKEONV"), 36000);
}

// Brake thresholds 360/340 -> 190/170 are lowered bottom-up (manual's example): BRAKEOFFV
// first. Applying the same profile again writes nothing: EEPROM cells wear out.
TEST_F(ProfileCli, ApplyVerifiesAndASecondApplyWritesNothing) {
  auto r = apply({shipped("line-120v.yaml")});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 6 values written, reset needed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Reset needed"), std::string::npos) << r.out;
  EXPECT_LT(r.out.find("NVBRAKEOFFV"), r.out.find("NVBRAKEONV")) << "safe order: " << r.out;
  EXPECT_EQ(eeprom_writes(sim.trace()), 6u);
  EXPECT_EQ(card("NVBRAKEONV"), 19000);
  EXPECT_EQ(card("NVBRAKEOFFV"), 17500);
  EXPECT_EQ(card("NVMAXCURRENT"), 1200);
  ASSERT_EQ(backups_in(dir.path()).size(), 1u);

  r = apply({shipped("line-120v.yaml")});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("NOTHING TO DO: the card already holds all 6 values; nothing was written"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("not live yet: 6"), std::string::npos) << "no reset since the first apply: " << r.out;
  EXPECT_EQ(eeprom_writes(sim.trace()), 6u) << "the second apply must not write the EEPROM";
  EXPECT_EQ(backups_in(dir.path()).size(), 1u) << "nothing written, no backup needed";

  ASSERT_EQ(i20({"reset", "--yes"}).exit_code, 0);
  r = apply({shipped("line-120v.yaml")});
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_EQ(r.out.find("Reset needed"), std::string::npos) << "live after the reset: " << r.out;
}

TEST_F(ProfileCli, BackupHoldsThePreviousValuesAndReapplies) {
  ASSERT_EQ(apply({shipped("line-120v.yaml")}).exit_code, 0);
  const auto backups = backups_in(dir.path());
  ASSERT_EQ(backups.size(), 1u);
  const auto text = slurp_file(backups[0]);
  EXPECT_NE(text.find("NVBRAKEONV: 360.00 V"), std::string::npos) << text;
  EXPECT_NE(text.find("8I20 unit 0x00012345"), std::string::npos) << "provenance: " << text;
  const auto r = apply({backups[0].string()});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 6 values written"), std::string::npos) << r.out;
  EXPECT_EQ(card("NVBRAKEONV"), 36000);
  EXPECT_EQ(card("NVBUSOVERV"), 38500);
}

TEST_F(ProfileCli, ApplyJsonIsCompleteForScripts) {
  sim.control("busv 48");  // the bench supply the profile is for
  const auto r =
      i20({"--json", "profile", "apply", shipped("bench-48v.yaml"), "--backup-dir", dir.path().string()});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const auto j = json(r);
  EXPECT_EQ(outcome(j), "done");
  EXPECT_TRUE(j["ok"].as<bool>());
  EXPECT_EQ(j["exit_code"].as<int>(), 0);
  EXPECT_EQ(j["profile"].as<std::string>(), "bench-48v");
  EXPECT_NE(j["card"].as<std::string>().find("SWREVISION 0xE120"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(j["backup"].as<std::string>()));
  EXPECT_EQ(j["plan"]["steps"].size(), 5u);
  ASSERT_EQ(j["plan"]["unchanged"].size(), 1u) << "the simulator's MAXCURRENT is 10 A already";
  EXPECT_EQ(j["plan"]["unchanged"][0]["cell"].as<std::string>(), "NVMAXCURRENT");
  EXPECT_EQ(j["writes"].size(), 5u);
  EXPECT_EQ(j["writes"][0]["ok"].as<bool>(), true);
  EXPECT_TRUE(j["reset_needed"].as<bool>());
  expect_report_matches_card(
      j, [&](const std::string& c) { return card(c); }, "bench-48v");
}

TEST_F(ProfileCli, SaveThenApplyRoundTrips) {
  ASSERT_EQ(i20({"set", "NVBRAKEONV=320V", "NVBRAKEOFFV=300V", "NVMAXCURRENT=7.5A"}).exit_code, 0);
  const auto saved = (dir / "x-axis.yaml").string();
  auto r = i20({"profile", "save", saved});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("Saved "), std::string::npos) << r.out;
  EXPECT_EQ(i20({"profile", "save", saved}).exit_code, 2) << "never overwrites a saved card by accident";
  EXPECT_EQ(run("i20", {"profile", "validate", saved}).exit_code, 0) << slurp_file(saved);

  ASSERT_EQ(apply({shipped("defaults.yaml")}).exit_code, 0);
  ASSERT_EQ(apply({shipped("line-120v.yaml")}).exit_code, 0);
  EXPECT_EQ(card("NVMAXCURRENT"), 1200);
  r = apply({saved});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(card("NVBRAKEONV"), 32000);
  EXPECT_EQ(card("NVBRAKEOFFV"), 30000);
  EXPECT_EQ(card("NVMAXCURRENT"), 750);
  r = i20({"profile", "diff", saved});
  EXPECT_NE(r.out.find("holds every value"), std::string::npos) << r.out;
}

TEST_F(ProfileCli, InvalidProfileIsRefusedBeforeAnythingIsWritten) {
  const auto before = sim.commands_seen();
  const auto typo = write_file(dir / "typo.yaml", "name: typo\nparameters:\n  NVBRAKONV: 190 V\n");
  auto r = apply({typo});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(typo + ":3: error: NVBRAKONV"), std::string::npos) << r.err;
  EXPECT_EQ(sim.commands_seen(), before) << "a profile that does not load opens no link";

  const auto brake = write_file(dir / "brake.yaml", kBrakeOnly);
  r = apply({brake});
  EXPECT_EQ(r.exit_code, 3) << "a broken rule is a refusal: " << r.out;
  EXPECT_NE(r.out.find("[brake-order]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("REFUSED by the rule above; nothing was written"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("refused: NVBRAKEONV: NVBRAKEOFFV 340.00 V (card) must be below"), std::string::npos)
      << r.err;
  EXPECT_EQ(data_writes(sim.trace()), 0u);
  EXPECT_TRUE(backups_in(dir.path()).empty());
}

TEST_F(ProfileCli, SafetyRuleRefusalExitsThreeAndWritesNothing) {
  SimProcess unknown_firmware({"--busv", "160", "--random-map", "5"});
  const auto live = write_file(dir / "live.yaml", "name: live\ntarget: working\nparameters:\n  KQP: 60\n");
  const auto r =
      i20_on(unknown_firmware.port(), {"profile", "apply", live, "--backup-dir", dir.path().string()});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("REFUSED: the card cannot read KQP as a fact"), std::string::npos) << r.out;
  EXPECT_EQ(data_writes(unknown_firmware.trace()), 0u);
}

TEST_F(ProfileCli, ToWorkingTriesAProfileLiveFirst) {
  const auto r = apply({shipped("line-120v.yaml"), "--to", "working"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 6 values written"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("reset needed"), std::string::npos) << "working values are live: " << r.out;
  EXPECT_EQ(card("BRAKEONV"), 19000);
  EXPECT_EQ(card("NVBRAKEONV"), 36000) << "the EEPROM is untouched";
  EXPECT_EQ(eeprom_writes(sim.trace()), 0u);
}

TEST_F(ProfileCli, ResetAfterApplyAsksAndWithYesMakesTheValuesLive) {
  const auto before = sim.commands_seen();
  auto r = apply({shipped("line-120v.yaml"), "--reset"});  // stdin is not a terminal
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--yes"), std::string::npos) << r.err;
  EXPECT_EQ(sim.commands_seen(), before) << "nothing sent before the question is answered";
  r = apply({shipped("line-120v.yaml"), "--reset", "--yes"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 6 values written and the card was reset: they are live now"),
            std::string::npos)
      << r.out;
  EXPECT_NE(sim.trace().find("fe 5a"), std::string::npos);
  EXPECT_EQ(card("BRAKEONV"), 19000) << "the reset loaded the EEPROM into the working values";
}

TEST_F(ProfileCli, CardNotReachedExitsOne) {
  const auto r = run("i20", {"profile", "apply", shipped("line-120v.yaml"), "--target",
                             "/dev/i20-no-such-port", "--backup-dir", dir.path().string()});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("NOT REACHED"), std::string::npos) << r.out;
  EXPECT_TRUE(backups_in(dir.path()).empty());
}
