// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 report` as a field technician uses it, against `i20sim --pty`: the snapshot says
// what the card holds (identity, firmware and map, every parameter, NV values not live yet,
// FAULT/STATUS decoded, link figures), writes nothing, and its parameters section applied
// to another card gives that card the same NV setup.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>

#include "harness.hpp"

using namespace i20::test;

namespace {

const std::map<std::string, std::string> kEnv{
    {"I20_PARAMS", ""}, {"XDG_CONFIG_HOME", "/nonexistent"}, {"COMPORT", ""}};

std::vector<std::string> names_in(const YAML::Node& list) {
  std::vector<std::string> out;
  for (const auto& n : list) out.push_back(n.as<std::string>());
  return out;
}

bool contains(const std::vector<std::string>& items, const std::string& item) {
  return std::find(items.begin(), items.end(), item) != items.end();
}

YAML::Node value_entry(const YAML::Node& report, const std::string& name) {
  for (const auto& v : report["report"]["values"])
    if (v["name"].as<std::string>() == name) return v;
  return {};
}

class Report : public ::testing::Test {
 protected:
  // A card with a latched NOENABLEFAULT and an NV value written but not yet live.
  Report() : sim({"--unit-number", "0x00C0FFEE"}) {
    sim.control("enable off");
    sim.control("set NVMAXCURRENT 2500");  // 25 A in the EEPROM, MAXCURRENT still 10 A
  }
  Result i20(std::vector<std::string> args, const SimProcess& card) {
    args.insert(args.begin(), {"--port", card.port()});
    return run("i20", args, kEnv);
  }
  TempDir dir;
  SimProcess sim;
};

}  // namespace

TEST_F(Report, SaysWhatTheCardHoldsAndWritesNothing) {
  const auto file = (dir / "card.yaml").string();
  const auto r = i20({"report", "-o", file}, sim);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(sim.writes_seen(), 0u) << "a report is read-only";

  const YAML::Node y = YAML::LoadFile(file);
  const auto rep = y["report"];
  EXPECT_EQ(rep["tool"].as<std::string>().rfind("i20tools ", 0), 0u);
  EXPECT_EQ(rep["time"].as<std::string>().size(), std::string("2026-12-01T20:44:20Z").size());
  EXPECT_EQ(rep["card"]["name"].as<std::string>(), "8I20");
  EXPECT_EQ(rep["card"]["unit_number"].as<unsigned>(), 0x00C0FFEEu);
  EXPECT_EQ(rep["card"]["swrevision"].as<unsigned>(), 0xE120u);
  EXPECT_TRUE(rep["card"]["working_map_confirmed"].as<bool>());
  EXPECT_EQ(rep["card"]["crc_errors"].as<int>(), 0);
  EXPECT_TRUE(contains(names_in(rep["card"]["rpc_confirmed"]), "FAULT"));

  // FAULT/STATUS decoded (manual: NOENABLEFAULT is FAULT bit 1, NOENABLESTATUS STATUS bit 8).
  EXPECT_EQ(rep["faults"]["fault"].as<unsigned>(), 0x0002u);
  EXPECT_EQ(names_in(rep["faults"]["fault_bits"]), std::vector<std::string>{"NOENABLEFAULT"});
  EXPECT_TRUE(contains(names_in(rep["faults"]["status_bits"]), "NOENABLESTATUS"));

  // Every parameter, NV values not live yet named.
  EXPECT_EQ(value_entry(y, "NVMAXCURRENT")["raw"].as<int>(), 2500);
  EXPECT_EQ(value_entry(y, "MAXCURRENT")["raw"].as<int>(), 1000);
  EXPECT_EQ(value_entry(y, "BUSV")["value"].as<std::string>(), "320.00 V");
  EXPECT_TRUE(contains(names_in(rep["nv_not_live_yet"]), "NVMAXCURRENT"));
  EXPECT_FALSE(contains(names_in(rep["nv_not_live_yet"]), "NVBRAKEONV"));
  EXPECT_GT(rep["link"]["commands"].as<int>(), 0);
  EXPECT_EQ(rep["link"]["crc_errors"].as<int>(), 0);

  // The profile part holds the NV setup in engineering units.
  EXPECT_EQ(y["parameters"]["NVMAXCURRENT"].as<std::string>(), "25.00 A");
  EXPECT_EQ(y["parameters"]["NVBRAKEONV"].as<std::string>(), "360.00 V");
}

TEST_F(Report, AppliedToAnotherCardGivesItTheSameNvSetup) {
  const auto file = (dir / "card.yaml").string();
  ASSERT_EQ(i20({"report", "-o", file}, sim).exit_code, 0);
  SimProcess spare({"--busv", "320"});
  ASSERT_EQ(spare.control("get NVMAXCURRENT"), "1000");
  const auto r = i20({"profile", "apply", file, "--yes"}, spare);
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  for (const char* name : {"NVMAXCURRENT", "NVBRAKEONV", "NVBRAKEOFFV", "NVBUSOVERV", "NVKQP", "NVKDI"})
    EXPECT_EQ(spare.control(std::string("get ") + name), sim.control(std::string("get ") + name)) << name;
  // Applying the report to the card it came from has nothing to do.
  const auto again = i20({"profile", "apply", file, "--yes"}, sim);
  EXPECT_EQ(again.exit_code, 0) << again.out << again.err;
  EXPECT_EQ(sim.writes_seen(), 0u) << "every cell already held its value";
}

TEST_F(Report, JsonCarriesTheSameFacts) {
  const auto r = i20({"--json", "report"}, sim);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  EXPECT_EQ(j["card"]["unit_number"].as<unsigned>(), 0x00C0FFEEu);
  EXPECT_EQ(j["faults"]["fault"].as<unsigned>(), 2u);
  EXPECT_EQ(j["faults"]["fault_hex"].as<std::string>(), "0x0002");
  EXPECT_TRUE(contains(names_in(j["nv_not_live_yet"]), "NVMAXCURRENT"));
  bool seen = false;
  for (const auto& v : j["values"])
    if (v["name"].as<std::string>() == "NVMAXCURRENT")
      seen = v["raw"].as<int>() == 2500 && v["fact"].as<bool>();
  EXPECT_TRUE(seen);
}

TEST_F(Report, RefusesToReplaceAFileUnlessAsked) {
  const auto file = dir / "card.yaml";
  std::ofstream(file) << "keep me\n";
  const auto r = i20({"report", "-o", file.string()}, sim);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "i20: error: " + file.string() +
                       " exists; pass --overwrite to replace it (or choose another name)\n");
  std::ifstream in(file);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "keep me\n");
  EXPECT_EQ(i20({"report", "-o", file.string(), "--overwrite"}, sim).exit_code, 0);
}

TEST(ReportUnknownMap, WorkingValuesOfAnUnconfirmedMapAreUnknownNotFacts) {
  SimProcess sim({"--random-map", "7"});
  const auto r = run("i20", {"--port", sim.port(), "--json", "report"}, kEnv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  EXPECT_FALSE(j["card"]["working_map_confirmed"].as<bool>());
  for (const auto& v : j["values"]) {
    const auto name = v["name"].as<std::string>();
    if (name == "KQP" || name == "BRAKEONV") {
      EXPECT_FALSE(v["fact"].as<bool>()) << name << " read from a guessed address";
      EXPECT_TRUE(v["raw"].IsNull()) << name;
    }
  }
  // FAULT/STATUS still come as facts: the pre-loaded RPC table names their addresses.
  EXPECT_TRUE(j["faults"].IsMap()) << r.out;
}
