// SPDX-License-Identifier: GPL-2.0-or-later
// The example profiles in profiles/ load and validate without a single finding, and say
// what the manual says.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <map>

#include "profile/loader.hpp"
#include "profile/tune.hpp"
#include "profile/tuning_profile.hpp"
#include "profile/validate.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;
namespace fs = std::filesystem;

namespace {

fs::path profiles_dir() {
  const char* root = std::getenv("I20_SOURCE_DIR");
  return fs::path(root ? root : ".") / "profiles";
}

Profile shipped(const std::string& name) {
  return load_profile_file(profiles_dir() / name, db());
}

std::map<std::string, std::int64_t> values_of(const Profile& p) {
  std::map<std::string, std::int64_t> out;
  for (const auto& s : p.settings) out[s.name] = s.raw;
  return out;
}

}  // namespace

TEST(ProfileShipped, EveryProfileValidatesCleanly) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(profiles_dir())) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    SCOPED_TRACE(entry.path().string());
    const Profile p = load_profile_file(entry.path(), db());
    const auto findings = validate(p, db());
    EXPECT_TRUE(findings.empty()) << dump(findings);
  }
  EXPECT_GE(count, 6);
}

// Issue 20, item 4: every shipped profile against every rule, offline, on a factory card (the
// simulator's values, NVBUSUNDERVMAX 40 V among them), and with the card measuring the bus the
// profile is for: with and without a bus context. Not one finding in any of them.
TEST(ProfileShipped, EveryProfileAgainstEveryRuleOnItsOwnSupply) {
  RawValues factory;
  for (const auto& p : db().all())
    if (p.default_value) factory[p.name] = *p.default_value;
  for (const auto& p : db().all())  // a working value starts from its NV twin at reset
    if (!p.is_nv() && !p.twin.empty() && !factory.contains(p.name) && factory.contains(p.twin))
      factory[p.name] = factory.at(p.twin);
  factory["NVMAXCURRENT"] = factory["MAXCURRENT"] = 1000;  // the simulator's (no published factory value)
  factory["NVBUSUNDERVMAX"] = factory["BUSUNDERVMAX"] = 4000;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(profiles_dir())) {
    if (entry.path().extension() != ".yaml") continue;
    ++count;
    SCOPED_TRACE(entry.path().string());
    const Profile p = load_profile_file(entry.path(), db());
    ASSERT_TRUE(p.supply.bus_voltage_v) << "every shipped profile says which supply it is for";
    const double bus = *p.supply.bus_voltage_v;
    for (const bool with_card : {false, true})
      for (const std::optional<double> measured : {std::optional<double>(), std::optional<double>(bus)}) {
        SCOPED_TRACE(
            std::string(with_card ? "factory card" : "no card") +
            (measured ? ", bus measured at " + std::to_string(*measured) + " V" : ", bus not measured"));
        const auto findings = validate(p, db(), {with_card ? &factory : nullptr, false, measured});
        EXPECT_TRUE(findings.empty()) << dump(findings);
      }
    // Every threshold it writes in both spaces, the way `reset` judges pending NV values.
    RawValues written;
    for (const auto& w : cell_writes(p, db())) written[w.cell] = w.raw;
    EXPECT_TRUE(measured_bus_findings(written, bus, db(), false).empty());
  }
  EXPECT_GE(count, 6);
}

TEST(ProfileShipped, DefaultsAreTheManualsDefaults) {
  const auto v = values_of(shipped("defaults.yaml"));
  EXPECT_EQ(v.size(), 8u);
  for (const auto& [name, raw] : v) EXPECT_EQ(raw, *db().get(name).default_value) << name;
  EXPECT_EQ(v.at("NVBRAKEONV"), 36000);
  EXPECT_EQ(v.at("NVBRAKEOFFV"), 34000);
  EXPECT_EQ(v.at("NVBUSOVERV"), 38500);
  EXPECT_EQ(v.at("NVKQP"), 50);
  EXPECT_EQ(v.at("NVKQI"), 150000);
}

// Manual, BRAKEONV and BRAKEOFFV: "WPD NVBRAKEONV 19000 / WPD NVBRAKEOFFV 17000 would be
// suitable values for a 120V line operated supply with a maximum rating of 200V." The brake-on
// is the manual's; the brake-off sits above the rectified line (120 V x 1.414 = 170 V), where
// an off threshold at or below the bus would keep the brake on after braking.
TEST(ProfileShipped, Line120KeepsTheManualsBrakeOnAndItsBrakeOffAboveTheBus) {
  const Profile p = shipped("line-120v.yaml");
  const auto v = values_of(p);
  EXPECT_EQ(v.at("NVBRAKEONV"), 19000);
  EXPECT_GT(v.at("NVBRAKEOFFV"), 17000);
  EXPECT_GT(static_cast<double>(v.at("NVBRAKEOFFV")) / 100, *p.supply.bus_voltage_v);
  EXPECT_LT(v.at("NVBUSOVERV"), 20000);  // below the supply's 200 V rating
  EXPECT_LT(v.at("NVBUSUNDERV"), v.at("NVBUSUNDERVMAX"));
}

// The manual's default 360/340 V brake is chosen for a 240 V line, whose bus (~340 V) sits on
// the brake-off; the profile keeps the manual's 20 V hysteresis above it.
TEST(ProfileShipped, Line240KeepsTheBrakeAboveTheBus) {
  const Profile p = shipped("line-240v.yaml");
  const auto v = values_of(p);
  EXPECT_GT(static_cast<double>(v.at("NVBRAKEOFFV")) / 100, *p.supply.bus_voltage_v);
  EXPECT_EQ(v.at("NVBRAKEONV") - v.at("NVBRAKEOFFV"), 2000);
  EXPECT_LE(v.at("NVBRAKEONV"), 38500);  // under the fixed 385 V brake-on (MOTOR BRAKE)
  EXPECT_LT(v.at("NVBUSUNDERV"), v.at("NVBUSUNDERVMAX"));
}

TEST(ProfileShipped, BenchKeepsEverythingLow) {
  const Profile p = shipped("bench-48v.yaml");
  const auto v = values_of(p);
  EXPECT_LE(v.at("NVBUSOVERV"), 8500);  // well below the supply's 100 V capacitors
  EXPECT_LT(v.at("NVBRAKEONV"), v.at("NVBUSOVERV"));
  EXPECT_EQ(v.at("NVBUSUNDERV"), 2400);
  EXPECT_DOUBLE_EQ(*p.supply.bus_voltage_v, 48.0);
}

// The tuning profiles hold what the calculator gives for their own metadata.
TEST(ProfileShipped, TuningProfilesMatchTheCalculator) {
  const std::map<std::string, double> bandwidth_hz{{"tune-reference-400w.yaml", 500.0},
                                                   {"tune-bench-48v.yaml", 500.0}};
  for (const auto& [file, bw] : bandwidth_hz) {
    SCOPED_TRACE(file);
    const Profile p = shipped(file);
    const auto t = tune(tune_request_from(p, db(), bw), db());
    const auto v = values_of(p);
    EXPECT_EQ(v.at("NVKQP"), t.kp);
    EXPECT_EQ(v.at("NVKDP"), t.kp);
    EXPECT_EQ(v.at("NVKQI"), t.ki);
    EXPECT_EQ(v.at("NVKDI"), t.ki);
  }
  const auto ref = values_of(shipped("tune-reference-400w.yaml"));
  EXPECT_EQ(ref.at("NVKQP"), 50);
  EXPECT_EQ(ref.at("NVKQI"), 150000);
}
