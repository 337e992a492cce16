// SPDX-License-Identifier: GPL-2.0-or-later
// i20 profile export (HAL setp / setsserial lines for LinuxCNC) and profiles found by name,
// as processes. Export is offline; the round trip reads a simulated card.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <sstream>

#include "cli_profile_util.hpp"

using namespace i20::test;
namespace fs = std::filesystem;

namespace {

bool has_line(const std::string& text, const std::string& line) {
  return ("\n" + text).find("\n" + line + "\n") != std::string::npos;
}

// name -> value of every `setp DEVICE.name value` line.
std::map<std::string, long> setp_values(const std::string& text, const std::string& device) {
  std::map<std::string, long> values;
  std::istringstream in(text);
  std::string word, name;
  long value = 0;
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    if (fields >> word >> name >> value && word == "setp" && name.rfind(device + ".", 0) == 0)
      values[name.substr(device.size() + 1)] = value;
  }
  return values;
}

}  // namespace

TEST(ProfileExportCli, HalLinesForAShippedProfileByName) {
  const auto r = run("i20", {"profile", "export", "line-120v", "--hal"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The manual's 120 V example: brake on 190 V, off 170 V, as raw 10 mV EEPROM words.
  EXPECT_TRUE(has_line(r.out, "setp hm2_7i96s.0.8i20.0.0.nvbrakeonv 19000")) << r.out;
  EXPECT_TRUE(has_line(r.out, "setp hm2_7i96s.0.8i20.0.0.nvbrakeoffv 17500")) << r.out;
  EXPECT_TRUE(has_line(r.out, "setp hm2_7i96s.0.8i20.0.0.nvbusundervmin 9000")) << r.out;
  EXPECT_TRUE(has_line(r.out, "setp hm2_7i96s.0.8i20.0.0.nvmaxcurrent 1200")) << r.out;
}

TEST(ProfileExportCli, SetsserialToAFileThatIsNeverOverwrittenByAccident) {
  TempDir dir;
  const std::string out = (dir / "axis.hal").string();
  auto r = run("i20", {"profile", "export", shipped("defaults.yaml"), "--setsserial", "--device",
                       "hm2_8i20.001f", "-o", out});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("to " + out), std::string::npos) << r.out;
  const std::string text = slurp_file(out);
  EXPECT_TRUE(has_line(text, "loadrt setsserial cmd=\"set hm2_8i20.001f.nvkqilo 18928\"")) << text;
  EXPECT_TRUE(has_line(text, "loadrt setsserial cmd=\"set hm2_8i20.001f.nvkqihi 2\"")) << text;

  write_file(out, "keep me\n");
  r = run("i20", {"profile", "export", shipped("defaults.yaml"), "--setsserial", "-o", out});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("--overwrite"), std::string::npos) << r.err;
  EXPECT_EQ(slurp_file(out), "keep me\n");
  r = run("i20", {"profile", "export", shipped("defaults.yaml"), "--setsserial", "-o", out, "--overwrite"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(slurp_file(out), "keep me\n");
}

TEST(ProfileExportCli, BadInputIsRefusedAndNothingIsWritten) {
  TempDir dir;
  const std::string out = (dir / "out.hal").string();
  const auto bad =
      write_file(dir / "bad.yaml", "name: bad\nparameters:\n  NVBRAKEONV: 300 V\n  NVBRAKEOFFV: 320 V\n");
  auto r = run("i20", {"profile", "export", bad, "--hal", "-o", out});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("[brake-order]"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "an invalid profile exports nothing";

  r = run("i20", {"profile", "export", shipped("defaults.yaml")});
  EXPECT_EQ(r.exit_code, 2) << "one of --hal or --setsserial is needed";
  EXPECT_NE(r.err.find("--hal or --setsserial"), std::string::npos) << r.err;
  r = run("i20", {"profile", "export", shipped("defaults.yaml"), "--hal", "--setsserial"});
  EXPECT_EQ(r.exit_code, 2);
  r = run("i20",
          {"profile", "export", shipped("defaults.yaml"), "--hal", "--device", "hm2_7i96s.0 ; x", "-o", out});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("is not a hostmot2 8I20 name"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));

  // NVBAUDRATE changes the link speed to the Ethernet card: guarded, as for apply.
  const auto baud = write_file(dir / "baud.yaml", "name: baud\nparameters:\n  NVBAUDRATE: 9\n");
  r = run("i20", {"profile", "export", baud, "--hal"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  r = run("i20", {"profile", "export", baud, "--hal", "--force"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "setp hm2_7i96s.0.8i20.0.0.nvrembaudrate 9")) << r.out;
}

TEST(ProfileExportCli, JsonListsEveryHalParameter) {
  const auto r =
      run("i20", {"--json", "profile", "export", "line-240v", "--hal", "--device", "hm2_7i92t.0.8i20.1.3"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  EXPECT_EQ(j["format"].as<std::string>(), "hal");
  ASSERT_TRUE(j["settings"].IsSequence());
  ASSERT_GT(j["settings"].size(), 0u);
  for (const auto& s : j["settings"]) {
    EXPECT_EQ(s["hal_parameter"].as<std::string>().rfind("hm2_7i92t.0.8i20.1.3.nv", 0), 0u);
    EXPECT_LE(s["value"].as<long>(), 0xFFFF) << "hostmot2 NV parameters are 16-bit words";
  }
}

// The round trip of the README: a card saved to a profile, exported for LinuxCNC, gives
// exactly the card's EEPROM words.
TEST(ProfileExportCli, ExportOfASavedCardCarriesTheCardsEepromWords) {
  SimProcess sim;
  TempDir dir;
  const std::string saved = (dir / "axis.yaml").string();
  ASSERT_EQ(i20_on(sim.port(), {"set", "NVBRAKEONV=375V", "NVBRAKEOFFV=355V", "NVKQI=123456", "NVKDI=123456"})
                .exit_code,
            0);
  ASSERT_EQ(i20_on(sim.port(), {"profile", "save", saved}).exit_code, 0);
  const auto r = run("i20", {"profile", "export", saved, "--hal", "--device", "hm2_7i96s.0.8i20.0.2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto hal = setp_values(r.out, "hm2_7i96s.0.8i20.0.2");
  const std::map<std::string, std::string> single = {{"nvmaxcurrent", "NVMAXCURRENT"},
                                                     {"nvbrakeonv", "NVBRAKEONV"},
                                                     {"nvbrakeoffv", "NVBRAKEOFFV"},
                                                     {"nvbusoverv", "NVBUSOVERV"},
                                                     {"nvbusundervmin", "NVBUSUNDERV"},
                                                     {"nvkqp", "NVKQP"},
                                                     {"nvkdp", "NVKDP"}};
  for (const auto& [hal_name, db_name] : single) {
    ASSERT_TRUE(hal.count(hal_name)) << hal_name << " missing in\n" << r.out;
    EXPECT_EQ(hal.at(hal_name), sim_value(sim, db_name)) << hal_name;
  }
  ASSERT_TRUE(hal.count("nvkqilo") && hal.count("nvkqihi")) << r.out;
  EXPECT_EQ(hal.at("nvkqilo") + (hal.at("nvkqihi") << 16), 123456);
  EXPECT_EQ(sim_value(sim, "NVKQI"), 123456);
}

TEST(ProfileByNameCli, FoundFromThePathListThenTheShippedOnes) {
  TempDir dir;
  write_file(dir / "mine.yaml", "name: mine\nparameters:\n  NVBRAKEONV: 370 V\n");
  auto r = run("i20", {"profile", "validate", "mine"}, {{"I20_PROFILE_PATH", dir.path().string()}});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find((dir / "mine.yaml").string() + ": valid"), std::string::npos) << r.out;
  // A shipped profile by name still works with a path list that does not have it.
  r = run("i20", {"profile", "validate", "bench-48v"}, {{"I20_PROFILE_PATH", dir.path().string()}});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;

  r = run("i20", {"profile", "validate", "nosuch"}, {{"I20_PROFILE_PATH", dir.path().string()}});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("profile 'nosuch' not found"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find((dir / "nosuch").string() + "[.yaml] ($I20_PROFILE_PATH)"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("(source tree)"), std::string::npos) << "a build-tree run also looks in profiles/";
}
