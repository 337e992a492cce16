// SPDX-License-Identifier: GPL-2.0-or-later
// i20 profile apply against simulators that misbehave: garbled replies, a card that resets
// itself mid-apply, power lost during an EEPROM write, a cell that does not take its value.
// Every run must end applied and verified, or rolled back and reported, and what the
// command reports must be what the card holds when read back independently afterwards.
#include <gtest/gtest.h>

#include <chrono>
#include <set>
#include <sstream>
#include <thread>

#include "cli_profile_util.hpp"

using namespace i20::test;

namespace {

const std::vector<std::string> kLine120vCells{"NVBUSUNDERV", "NVBRAKEOFFV", "NVBRAKEONV", "NVBUSOVERV",
                                              "NVMAXCURRENT"};
const std::set<std::string> kFinished{"done", "nothing-to-do", "rolled-back",
                                      "uncertain"};

class ProfileCliFaults : public ::testing::Test {
 protected:
  Result apply_json(SimProcess& sim, const std::string& profile, std::vector<std::string> extra = {}) {
    std::vector<std::string> args{"--json", "profile", "apply", profile, "--backup-dir", dir.path().string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return i20_on(sim.port(), args);
  }

  // The exit code says what the report says: 0 only for a verified card.
  static void expect_exit_code_matches(const Result& r, const YAML::Node& j, const std::string& label) {
    const std::string what = outcome(j);
    const int want = what == "done" || what == "nothing-to-do" ? 0
                     : what == "failed"                                   ? 1
                     : what == "interrupted"                              ? 130
                     : what == "refused"                                       ? j["exit_code"].as<int>()
                                                                               : 4;
    EXPECT_EQ(r.exit_code, want) << label << ": " << what << "\n" << r.out;
    EXPECT_EQ(j["exit_code"].as<int>(), r.exit_code) << label;
  }

  // After the run, with the faults switched off: the card's own values against the report.
  static void expect_consistent(SimProcess& sim, const YAML::Node& j,
                                const std::map<std::string, std::int64_t>& before, const std::string& label) {
    if (outcome(j) == "failed" || !j["plan"] ||
        j["plan"]["steps"].size() + j["plan"]["unchanged"].size() == 0) {
      for (const auto& [cell, value] : before)
        EXPECT_EQ(sim_value(sim, cell), value)
            << label << ": never reached (or read), yet " << cell << " changed";
      return;
    }
    expect_report_matches_card(
        j, [&](const std::string& c) { return sim_value(sim, c); }, label);
  }

  static std::map<std::string, std::int64_t> snapshot(SimProcess& sim) {
    std::map<std::string, std::int64_t> values;
    for (const auto& c : kLine120vCells) values[c] = sim_value(sim, c);
    return values;
  }

  // Commands an apply of `profile` sends before its first write: a dry run does the
  // same reads, checks and plan, and stops there.
  std::size_t commands_before_first_write(const std::string& profile) {
    SimProcess probe{kLine120Bus};
    const auto before = probe.commands_seen();
    const auto r = apply_json(probe, profile, {"--dry-run"});
    EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
    return probe.commands_seen() - before;
  }

  TempDir dir;
};

}  // namespace

TEST_F(ProfileCliFaults, CorruptedRepliesEndVerifiedOrRolledBack) {
  std::size_t retries = 0;
  for (const std::string seed : {"1", "2", "3", "4", "5", "6"}) {
    const std::string label = "corrupt 0.02 seed " + seed;
    SimProcess sim({"--busv", "160", "--corrupt", "0.02", "--seed", seed});
    const auto before = snapshot(sim);
    const auto r = apply_json(sim, shipped("line-120v.yaml"));
    const auto j = json(r);
    expect_exit_code_matches(r, j, label);
    EXPECT_TRUE(kFinished.contains(outcome(j)) || outcome(j) == "failed" || outcome(j) == "refused")
        << label << ": " << r.out;
    if (j["retries"]) retries += j["retries"].as<std::size_t>();
    sim.control("corrupt 0");
    expect_consistent(sim, j, before, label);
  }
  EXPECT_GT(retries, 0u) << "the injection garbled no reply at all: the test proves nothing";
}

TEST_F(ProfileCliFaults, HeavilyCorruptedLineNeverLeavesTheCardSilentlyWrong) {
  for (const std::string seed : {"11", "12", "13", "14"}) {
    const std::string label = "corrupt 0.12 seed " + seed;
    SimProcess sim({"--busv", "160", "--corrupt", "0.12", "--seed", seed});
    const auto before = snapshot(sim);
    const auto r = apply_json(sim, shipped("line-120v.yaml"));
    const auto j = json(r);
    expect_exit_code_matches(r, j, label);
    sim.control("corrupt 0");
    expect_consistent(sim, j, before, label);
  }
}

TEST_F(ProfileCliFaults, LostRepliesEndVerifiedOrRolledBack) {
  for (const std::string seed : {"21", "22", "23"}) {
    const std::string label = "drop 0.1 seed " + seed;
    SimProcess sim({"--busv", "160", "--drop", "0.1", "--seed", seed});
    const auto before = snapshot(sim);
    const auto r = apply_json(sim, shipped("line-120v.yaml"));
    const auto j = json(r);
    expect_exit_code_matches(r, j, label);
    sim.control("drop 0");
    expect_consistent(sim, j, before, label);
  }
}

// The card resets itself (DSP watchdog) at different points of the writes. A reset leaves
// NV access mode and reloads the working values from a half-written EEPROM, so besides the
// outcome the report must say that the card reset.
TEST_F(ProfileCliFaults, CardResetMidApplyIsVerifiedOrRolledBackAndReported) {
  const auto lead = commands_before_first_write(shipped("line-120v.yaml"));
  std::set<std::string> outcomes;
  for (const std::size_t offset : {1u, 2u, 3u, 5u, 6u, 9u, 13u, 18u}) {
    const std::string label = "reset after " + std::to_string(lead + offset) + " commands";
    SimProcess sim{kLine120Bus};
    const auto before = snapshot(sim);
    ASSERT_EQ(sim.control("reset-after " + std::to_string(lead + offset)), "ok");
    const auto r = apply_json(sim, shipped("line-120v.yaml"));
    const auto j = json(r);
    outcomes.insert(outcome(j));
    expect_exit_code_matches(r, j, label);
    EXPECT_TRUE(kFinished.contains(outcome(j))) << label << ": " << r.out;
    ASSERT_NE(sim.trace().find("injected reset"), std::string::npos) << label << ": the reset never fired";
    EXPECT_NE(j["card_reset"].as<std::string>(), "") << label << ": the card's reset went unreported\n"
                                                     << r.out;
    expect_consistent(sim, j, before, label);
  }
  std::string seen;
  for (const auto& o : outcomes) seen += o + " ";
  RecordProperty("outcomes", seen);
}

TEST_F(ProfileCliFaults, ResetMidApplyIsToldInTheTextReport) {
  const auto lead = commands_before_first_write(shipped("line-120v.yaml"));
  SimProcess sim{kLine120Bus};
  ASSERT_EQ(sim.control("reset-after " + std::to_string(lead + 6)), "ok");
  const auto r = i20_on(sim.port(),
                        {"profile", "apply", shipped("line-120v.yaml"), "--backup-dir", dir.path().string()});
  EXPECT_NE(r.out.find("WARNING: the card reset itself during the change (STATUS WDTO"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("reset"), std::string::npos);
}

// Power fails during the first EEPROM write and the card stays dead: nothing can be
// restored, and the report says so cell by cell instead of guessing.
TEST_F(ProfileCliFaults, PowerLossDuringAnEepromWriteIsAClearlyReportedRollbackFailure) {
  for (const std::string mode : {"torn", "lost"}) {
    const std::string label = "eeprom-power-loss " + mode;
    SimProcess sim{kLine120Bus};
    const auto before = snapshot(sim);
    ASSERT_EQ(sim.control("eeprom-power-loss " + mode), "ok");
    const auto r = apply_json(sim, shipped("line-120v.yaml"));
    const auto j = json(r);
    EXPECT_EQ(r.exit_code, 4) << label << ": " << r.out << r.err;
    EXPECT_EQ(outcome(j), "uncertain") << label;
    ASSERT_GE(j["cells"].size(), 1u) << label;
    EXPECT_EQ(j["cells"][0]["status"].as<std::string>(), "unknown") << label;
    const auto backup = j["backup"].as<std::string>();
    ASSERT_TRUE(std::filesystem::exists(backup))
        << label << ": the backup was written before the first write";

    ASSERT_EQ(sim.control("power cycle"), "ok");
    expect_consistent(sim, j, before, label);
    // Back to a known state with the backup the report names.
    const auto restore =
        i20_on(sim.port(), {"--json", "profile", "apply", backup, "--backup-dir", dir.path().string()});
    EXPECT_EQ(restore.exit_code, 0) << label << ": " << restore.out << restore.err;
    for (const auto& [cell, value] : before) EXPECT_EQ(sim_value(sim, cell), value) << label << " " << cell;
  }
}

TEST_F(ProfileCliFaults, RollbackFailureTextNamesTheStateAndTheWayBack) {
  SimProcess sim{kLine120Bus};
  ASSERT_EQ(sim.control("eeprom-power-loss torn"), "ok");
  const auto r = i20_on(sim.port(),
                        {"profile", "apply", shipped("line-120v.yaml"), "--backup-dir", dir.path().string()});
  EXPECT_EQ(r.exit_code, 4);
  EXPECT_NE(r.out.find("ROLLBACK FAILED after NVBRAKEOFFV failed: card state below"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("UNKNOWN"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("profile apply " + dir.path().string()), std::string::npos)
      << "how to restore: " << r.out;
}

// An overlay that puts a parameter where the card's own RPC table says another one lives
// contradicts the card: refused when the card is opened, before anything is written.
TEST_F(ProfileCliFaults, AnOverlayTheCardContradictsIsRefusedBeforeAnyWrite) {
  SimProcess sim{kLine120Bus};
  const auto overlay = write_file(dir / "overlay.yaml",
                                  "parameters:\n"
                                  "  - name: BUSV\n    address: 0x0F00\n"
                                  "  - name: KQP\n    address: 0x0808\n");
  const auto r = i20_on(sim.port(), {"--params", overlay, "set", "KQP=60"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("BUSV: address overlaps KQP"), std::string::npos) << r.err;
  EXPECT_EQ(data_writes(sim.trace()), 0u) << sim.trace();
}

// Ctrl-C in the middle of the writes stops the apply, and what was written is restored
// before the program ends (a second one does not end it: tests/cli_signals).
TEST_F(ProfileCliFaults, CtrlCMidApplyRestoresWhatWasWritten) {
  SimProcess sim{kLine120Bus};
  const auto before = snapshot(sim);
  ASSERT_EQ(sim.control("delay 100"), "ok");  // slow replies: a wide window between the writes
  Background apply({"--port", sim.port(), "--no-user-params", "--timeout", "2000", "profile", "apply",
                    shipped("line-120v.yaml"), "--backup-dir", dir.path().string()});
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (eeprom_writes(sim.trace()) < 1 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_GE(eeprom_writes(sim.trace()), 1u) << "the apply never started writing";
  apply.interrupt();
  const auto r = apply.wait();
  ASSERT_EQ(sim.control("delay 0"), "ok");
  EXPECT_EQ(r.exit_code, 130) << "interrupted, after the card was left as it was: " << r.out << r.err;
  EXPECT_NE(r.out.find("INTERRUPTED AND ROLLED BACK: every value written was restored and read back"),
            std::string::npos)
      << r.out << r.err;
  for (const auto& [cell, value] : before) EXPECT_EQ(sim_value(sim, cell), value) << cell;
  std::istringstream trace(sim.trace());
  std::string last_mode;
  for (std::string line; std::getline(trace, line);)
    if (line.rfind("i20sim: ec ", 0) == 0) last_mode = line.substr(8, 5);
  EXPECT_EQ(last_mode, "ec 00") << "NV access mode is left at the end";
}
