// SPDX-License-Identifier: GPL-2.0-or-later
// i20 inventory --target T1 --target T2 ...: one row per amplifier, read-only; a card that
// does not answer is its own row and changes nothing for the others; --profile tells which
// cards hold the profile, by the comparison `profile diff` makes.
#include <gtest/gtest.h>

#include "cli_profile_util.hpp"

using namespace i20::test;

namespace {

class InventoryCli : public ::testing::Test {
 protected:
  Result inventory(const std::vector<std::string>& targets, std::vector<std::string> extra = {},
                   bool json_out = true) {
    std::vector<std::string> args{"--no-user-params"};
    if (json_out) args.push_back("--json");
    args.push_back("inventory");
    for (const auto& t : targets) args.insert(args.end(), {"--target", t});
    args.insert(args.end(), extra.begin(), extra.end());
    return run("i20", args, {}, 120);
  }
  // line-240v applied to a fresh simulator card whose EEPROM lives in `image`.
  void apply_240(const std::string& image) {
    const auto r = run("i20", {"--no-user-params", "--sim", "--sim-eeprom", image, "profile", "apply",
                               shipped("line-240v.yaml"), "--backup-dir", dir.path().string()});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  }
  std::string image(const std::string& name) { return (dir / name).string(); }
  // A fresh card's image on disk.
  std::string fresh(const std::string& name) {
    const auto path = image(name);
    EXPECT_EQ(run("i20", {"--no-user-params", "--sim", "--sim-eeprom", path, "info"}).exit_code, 0);
    return path;
  }

  TempDir dir;
};

}  // namespace

TEST_F(InventoryCli, OneRowPerCardWhetherItHoldsTheProfileAndTheDeadOneFailsAlone) {
  const auto a = fresh("a.eeprom"), b = fresh("b.eeprom");
  apply_240(a);
  const auto a_before = slurp_file(a), b_before = slurp_file(b);
  SimProcess dead({"--drop", "1"});  // executes everything, answers nothing
  const auto r = inventory({"sim:" + a, dead.port(), "sim:" + b}, {"--profile", shipped("line-240v.yaml")});
  EXPECT_EQ(r.exit_code, 1) << "a card not reached: " << r.out << r.err;
  const auto j = json(r);
  EXPECT_EQ(j["profile"].as<std::string>(), "line-240v");
  ASSERT_EQ(j["targets"].size(), 3u) << r.out;
  const auto row_a = j["targets"][0], row_dead = j["targets"][1], row_b = j["targets"][2];
  EXPECT_EQ(row_a["target"].as<std::string>(), "sim:" + a);
  EXPECT_EQ(row_a["outcome"].as<std::string>(), "done");
  EXPECT_TRUE(row_a["matches_profile"].as<bool>()) << r.out;
  EXPECT_EQ(row_a["differ"].as<int>(), 0);
  EXPECT_FALSE(row_b["matches_profile"].as<bool>())
      << "a fresh card holds the default under-voltage and current";
  EXPECT_GT(row_b["differ"].as<int>(), 0);
  EXPECT_EQ(row_dead["outcome"].as<std::string>(), "failed");
  EXPECT_TRUE(row_dead["matches_profile"].IsNull()) << "not read: not known";
  EXPECT_EQ(row_dead["target"].as<std::string>(), dead.port());
  for (const auto& row : {row_a, row_b}) {
    EXPECT_TRUE(row["working_map_confirmed"].as<bool>());
    EXPECT_GT(row["swrevision"].as<int>(), 0);
    EXPECT_EQ(row["fault"].as<int>(), 0);
    EXPECT_TRUE(row["linuxcnc_name"].IsNull()) << "a simulated card has no hostmot2 name";
  }
  EXPECT_EQ(slurp_file(a), a_before) << "read-only";
  EXPECT_EQ(slurp_file(b), b_before) << "read-only";
  EXPECT_EQ(data_writes(dead.trace()), 0u);
}

TEST_F(InventoryCli, TheSameComparisonAsProfileDiff) {
  const auto b = fresh("b.eeprom");
  const auto inv = json(inventory({"sim:" + b}, {"--profile", shipped("line-240v.yaml")}));
  const auto diff = json(run("i20", {"--no-user-params", "--json", "--sim", "--sim-eeprom", b, "profile",
                                     "diff", shipped("line-240v.yaml")}));
  const auto rows = inv["targets"][0]["rows"];
  ASSERT_EQ(rows.size(), diff["rows"].size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i]["cell"].as<std::string>(), diff["rows"][i]["cell"].as<std::string>());
    EXPECT_EQ(rows[i]["equal"].as<bool>(), diff["rows"][i]["equal"].as<bool>()) << rows[i]["cell"];
    EXPECT_EQ(rows[i]["card_raw"].as<long>(), diff["rows"][i]["card_raw"].as<long>());
  }
  EXPECT_EQ(inv["targets"][0]["differ"].as<int>(), diff["differ"].as<int>());
}

TEST_F(InventoryCli, ALatchedFaultIsNamedAndTheTableSaysNothingWasWritten) {
  SimProcess faulty;
  ASSERT_EQ(faulty.control("fault overcurrent on"), "ok");
  const auto a = fresh("a.eeprom");
  auto r = inventory({faulty.port(), "sim:" + a}, {}, false);
  EXPECT_EQ(r.exit_code, 0) << "reading a faulted card is a finished read: " << r.out << r.err;
  for (const char* header : {"TARGET", "UNIT", "FIRMWARE", "MAP", "LINUXCNC", "FAULTS"})
    EXPECT_NE(r.out.find(header), std::string::npos) << header << "\n" << r.out;
  EXPECT_EQ(r.out.find("PROFILE"), std::string::npos) << "no profile, no column";
  EXPECT_NE(r.out.find("confirmed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 of 2 amplifiers read; nothing was written"), std::string::npos) << r.out;
  r = inventory({faulty.port()});
  const auto bits = json(r)["targets"][0]["fault_bits"];
  ASSERT_TRUE(bits.IsSequence()) << r.out;
  ASSERT_GE(bits.size(), 1u) << r.out;
  bool overcurrent = false;
  for (const auto& bit : bits) overcurrent = overcurrent || bit.as<std::string>() == "CURRENTFAULT";
  EXPECT_TRUE(overcurrent) << r.out;
  EXPECT_EQ(faulty.writes_seen(), 0u) << "read-only";
}

TEST_F(InventoryCli, AProfileThatCannotBeReadSendsNothing) {
  SimProcess card;
  const auto bad = write_file(dir / "bad.yaml", "schema: 1\nname: bad\nparameters:\n  NVNOSUCHCELL: 90 V\n");
  const auto r = inventory({card.port()}, {"--profile", bad});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("NVNOSUCHCELL"), std::string::npos) << r.err;
  EXPECT_EQ(card.commands_seen(), 0u) << "nothing is sent before the profile loads";
}
