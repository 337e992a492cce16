// SPDX-License-Identifier: GPL-2.0-or-later
// Every validation rule, on both sides of its line, against the manual's statements.
#include "profile/validate.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

namespace {

std::vector<Finding> check(const std::string& yaml, const RawValues* card = nullptr, bool force = false) {
  return validate(load(yaml), db(), {card, force, std::nullopt});
}

std::vector<Finding> check_params(const std::string& lines, const std::string& extra = "",
                                  const RawValues* card = nullptr) {
  return check(with_params(lines, extra), card);
}

// A database whose ranges no longer stop out-of-rule values, so the rules are seen to act
// on their own (the database's ranges and the rules are two independent fences).
const i20::params::ParamDb& widened_db() {
  static const i20::params::ParamDb instance = [] {
    auto d = i20::params::ParamDb::builtin();
    d.apply_overlay_string(
        "schema: 1\nparameters:\n  - name: NVBRAKEONV\n    max: 40000\n  - name: NVMAXCURRENT\n    max: "
        "4000\n",
        "widen.yaml");
    return d;
  }();
  return instance;
}

}  // namespace

TEST(ProfileValidate, ManualDefaultsAreClean) {
  const auto f = check_params(
      "  NVBRAKEONV: 360 V\n  NVBRAKEOFFV: 340 V\n  NVBUSOVERV: 385 V\n  NVBUSUNDERV: 35 V\n"
      "  NVKQP: 50\n  NVKDP: 50\n  NVKQI: 150000\n  NVKDI: 150000\n");
  EXPECT_TRUE(f.empty()) << dump(f);
}

TEST(ProfileValidate, RangeComesFromTheDatabase) {
  auto f = check_params("  NVKQP: 65535\n  NVKDP: 65535\n");
  EXPECT_FALSE(has_rule(f, "range")) << dump(f);
  f = check_params("  NVKQP: 65536\n  NVKDP: 65536\n");
  ASSERT_TRUE(has_rule(f, "range", Severity::Error)) << dump(f);
  EXPECT_EQ(f[0].key, "NVKQP");
  EXPECT_EQ(f[0].where, "test.yaml:3");
  EXPECT_TRUE(has_rule(check_params("  NVMAXCURRENT: 30.01 A\n"), "range", Severity::Error));
  EXPECT_FALSE(has_rule(check_params("  NVMAXCURRENT: 30 A\n"), "range"));
  // "both" checks the working twin too.
  EXPECT_TRUE(
      has_rule(check_params("  NVKQP: {value: 70000, target: both}\n  NVKDP: {value: 70000, target: both}\n"),
               "range"));
}

TEST(ProfileValidate, ReadOnlyParametersAreNotSettings) {
  EXPECT_TRUE(has_rule(check_params("  BUSV: 48 V\n"), "read-only", Severity::Error));
  EXPECT_FALSE(has_rule(check_params("  BUSOVERV: 80 V\n"), "read-only"));
}

TEST(ProfileValidate, GuardedParametersNeedForce) {
  const std::string yaml = with_params("  NVBAUDRATE: 9\n");
  EXPECT_TRUE(has_rule(check(yaml), "guarded", Severity::Error));
  const auto forced = check(yaml, nullptr, true);
  EXPECT_TRUE(has_rule(forced, "guarded", Severity::Warning));
  EXPECT_FALSE(has_errors(forced)) << dump(forced);
}

// Manual, MOTOR BRAKE: "BrakeOn voltage must always be set higher than BrakeOff voltage."
TEST(ProfileValidate, BrakeOffMustBeBelowBrakeOn) {
  auto f = check_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 190 V\n");
  ASSERT_TRUE(has_rule(f, "brake-order", Severity::Error)) << dump(f);
  EXPECT_EQ(f[0].key, "NVBRAKEOFFV");
  EXPECT_EQ(f[0].where, "test.yaml:4");
  EXPECT_TRUE(has_rule(check_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 200 V\n"), "brake-order"));
  EXPECT_FALSE(has_rule(check_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 170 V\n"), "brake-order"));
  // Working values are judged among themselves.
  EXPECT_TRUE(has_rule(check_params("  BRAKEONV: 100 V\n  BRAKEOFFV: 120 V\n"), "brake-order"));
}

// Manual, BRAKEONV and BRAKEOFFV: "It is suggested that BRAKEOFFV be set 20V lower than BRAKEON."
TEST(ProfileValidate, BrakeHysteresisAbout20V) {
  EXPECT_FALSE(has_rule(check_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 170 V\n"), "brake-hysteresis"));
  EXPECT_FALSE(has_rule(check_params("  NVBRAKEONV: 75 V\n  NVBRAKEOFFV: 57 V\n"), "brake-hysteresis"));
  EXPECT_TRUE(has_rule(check_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 185 V\n"), "brake-hysteresis",
                       Severity::Warning));
  EXPECT_TRUE(has_rule(check_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 140 V\n"), "brake-hysteresis",
                       Severity::Warning));
}

// Manual, MOTOR BRAKE: a fixed 385 V BrakeOn protects the module; 385 V is the maximum setting.
TEST(ProfileValidate, BrakeOnNotAbove385V) {
  const auto yaml = with_params("  NVBRAKEONV: 390 V\n  NVBRAKEOFFV: 370 V\n  NVBUSOVERV: 395 V\n");
  const auto f = validate(load(yaml, widened_db()), widened_db());
  EXPECT_TRUE(has_rule(f, "brake-on-limit", Severity::Error)) << dump(f);
  const auto ok = with_params("  NVBRAKEONV: 385 V\n  NVBRAKEOFFV: 365 V\n  NVBUSOVERV: 395 V\n");
  EXPECT_FALSE(has_rule(validate(load(ok, widened_db()), widened_db()), "brake-on-limit"));
}

TEST(ProfileValidate, BrakeShouldEngageBeforeTheOverVoltageFault) {
  EXPECT_TRUE(has_rule(check_params("  NVBUSOVERV: 360 V\n"), "brake-below-overvoltage", Severity::Warning));
  EXPECT_FALSE(has_rule(check_params("  NVBUSOVERV: 361 V\n"), "brake-below-overvoltage"));
}

TEST(ProfileValidate, UnderVoltageBelowOverVoltage) {
  auto f = check_params("  NVBUSUNDERV: 100 V\n  NVBUSOVERV: 100 V\n");
  EXPECT_TRUE(has_rule(f, "undervoltage-below-overvoltage", Severity::Error)) << dump(f);
  f = check_params("  NVBUSUNDERV: 99.99 V\n  NVBUSOVERV: 100 V\n");
  EXPECT_FALSE(has_rule(f, "undervoltage-below-overvoltage")) << dump(f);
}

// Manual, MAXCURRENT: 30 A RMS is the card's maximum.
TEST(ProfileValidate, MaxCurrentWithinTheCard) {
  const auto over = validate(load(with_params("  NVMAXCURRENT: 30.5 A\n"), widened_db()), widened_db());
  EXPECT_TRUE(has_rule(over, "maxcurrent-card", Severity::Error)) << dump(over);
  const auto at = validate(load(with_params("  NVMAXCURRENT: 30 A\n"), widened_db()), widened_db());
  EXPECT_FALSE(has_rule(at, "maxcurrent-card")) << dump(at);
}

TEST(ProfileValidate, MaxCurrentWithinTheMotorsRating) {
  const std::string rated = "motor:\n  continuous_current: 2.7 A\n  peak_current: 8.1 A\n";
  // Up to the peak rating is what the manual asks for ("the maximum RMS motor current").
  EXPECT_FALSE(has_rule(check_params("  NVMAXCURRENT: 8.1 A\n", rated), "maxcurrent-motor"));
  EXPECT_TRUE(has_rule(check_params("  NVMAXCURRENT: 8.2 A\n", rated), "maxcurrent-motor", Severity::Error));
  // Without a peak rating: above continuous is a warning, far above it an error.
  const std::string cont_only = "motor:\n  continuous_current: 2.7 A\n";
  EXPECT_FALSE(has_rule(check_params("  NVMAXCURRENT: 2.7 A\n", cont_only), "maxcurrent-motor"));
  EXPECT_TRUE(
      has_rule(check_params("  NVMAXCURRENT: 2.8 A\n", cont_only), "maxcurrent-motor", Severity::Warning));
  EXPECT_TRUE(
      has_rule(check_params("  NVMAXCURRENT: 8.2 A\n", cont_only), "maxcurrent-motor", Severity::Error));
  // Judged on the card's value when the profile names the motor but does not set MAXCURRENT.
  const RawValues card{{"NVMAXCURRENT", 1500}};
  EXPECT_TRUE(has_rule(check_params("  NVKQP: 50\n  NVKDP: 50\n", rated, &card), "maxcurrent-motor"));
}

// Manual, CURRENT LOOP TUNING: "Normally KQP should equal KDP and KQI should equal KDI."
TEST(ProfileValidate, QAndDGainsNormallyEqual) {
  EXPECT_TRUE(has_rule(check_params("  NVKQP: 60\n  NVKDP: 50\n"), "kp-match", Severity::Warning));
  EXPECT_FALSE(has_rule(check_params("  NVKQP: 60\n  NVKDP: 60\n"), "kp-match"));
  EXPECT_TRUE(has_rule(check_params("  NVKQI: 200000\n  NVKDI: 150000\n"), "ki-match", Severity::Warning));
  EXPECT_FALSE(has_rule(check_params("  NVKQI: 200000\n  NVKDI: 200000\n"), "ki-match"));
}

// Rules judge what the card will hold: the other side from the card, else the default.
TEST(ProfileValidate, OneSidedSettingsUseTheCardOrTheDefault) {
  // Only NVBRAKEONV: against the default NVBRAKEOFFV of 340 V it is inverted.
  auto f = check_params("  NVBRAKEONV: 190 V\n");
  EXPECT_TRUE(has_rule(f, "brake-order", Severity::Error)) << dump(f);
  EXPECT_NE(f[0].message.find("NVBRAKEOFFV 340.00 V (default)"), std::string::npos) << f[0].message;
  // The card already has 170 V: fine.
  const RawValues card{{"NVBRAKEOFFV", 17000}};
  f = check_params("  NVBRAKEONV: 190 V\n", "", &card);
  EXPECT_FALSE(has_rule(f, "brake-order")) << dump(f);
  // Only KQP: compared with the card's KDP.
  const RawValues gains{{"NVKDP", 60}};
  EXPECT_FALSE(has_rule(check_params("  NVKQP: 60\n", "", &gains), "kp-match"));
  EXPECT_TRUE(has_rule(check_params("  NVKQP: 60\n"), "kp-match"));  // default NVKDP 50
}

TEST(ProfileValidate, SpacesTheProfileDoesNotTouchAreNotJudged) {
  // The card's working brake values are inverted, but this profile writes only EEPROM gains.
  const RawValues card{{"BRAKEONV", 10000}, {"BRAKEOFFV", 20000}};
  const auto f = check_params("  NVKQP: 50\n  NVKDP: 50\n", "", &card);
  EXPECT_TRUE(f.empty()) << dump(f);
  // Nor a rule whose cells the profile does not write.
  const RawValues nv_card{{"NVBRAKEONV", 10000}, {"NVBRAKEOFFV", 20000}};
  EXPECT_FALSE(has_rule(check_params("  NVKQP: 50\n  NVKDP: 50\n", "", &nv_card), "brake-order"));
}

TEST(ProfileValidate, SupplyRules) {
  const std::string bus48 = "supply:\n  bus_voltage: 48 V\n";
  const std::string bench =
      "  NVBRAKEONV: 75 V\n  NVBRAKEOFFV: 57 V\n  NVBUSOVERV: 80 V\n  NVBUSUNDERV: 24 V\n";
  EXPECT_TRUE(check_params(bench, bus48).empty()) << dump(check_params(bench, bus48));
  // The default 360/340 V brake with a 385 V fault on a 340 V bus is the manual's own setup.
  EXPECT_TRUE(check_params("  NVKQP: 50\n", "supply:\n  bus_voltage: 340 V\n").empty());

  EXPECT_TRUE(
      has_rule(check_params("  NVBUSUNDERV: 48 V\n", bus48), "bus-above-undervoltage", Severity::Error));
  EXPECT_FALSE(has_rule(check_params("  NVBUSUNDERV: 47 V\n", bus48), "bus-above-undervoltage"));
  EXPECT_TRUE(has_rule(
      check_params("  NVBUSOVERV: 48 V\n  NVBUSUNDERV: 24 V\n  NVBRAKEONV: 40 V\n  NVBRAKEOFFV: 20 V\n",
                   bus48),
      "bus-below-overvoltage", Severity::Error));
  EXPECT_FALSE(has_rule(check_params(bench, bus48), "bus-below-overvoltage"));
  // Brake on at or below the bus: the resistor burns the supply's power.
  EXPECT_TRUE(has_rule(check_params("  NVBRAKEONV: 48 V\n  NVBRAKEOFFV: 30 V\n", bus48), "brake-above-bus",
                       Severity::Error));
  // Brake off below the bus: once on it stays on.
  EXPECT_TRUE(has_rule(check_params("  NVBRAKEONV: 60 V\n  NVBRAKEOFFV: 45 V\n", bus48),
                       "brake-off-above-bus", Severity::Warning));
  EXPECT_FALSE(
      has_rule(check_params("  NVBRAKEONV: 68 V\n  NVBRAKEOFFV: 48 V\n", bus48), "brake-off-above-bus"));
  // The card takes 400 V at most.
  EXPECT_TRUE(has_rule(check_params("  NVKQP: 50\n", "supply:\n  bus_voltage: 410 V\n"), "bus-card-limit",
                       Severity::Error));
  EXPECT_FALSE(has_rule(check_params("  NVKQP: 50\n", "supply:\n  bus_voltage: 400 V\n"), "bus-card-limit"));
}

TEST(ProfileValidate, ReportsAllFindingsAtOnce) {
  const auto f = check_params("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 195 V\n  NVKQP: 70000\n  BUSV: 10 V\n");
  EXPECT_TRUE(has_rule(f, "brake-order"));
  EXPECT_TRUE(has_rule(f, "range"));
  EXPECT_TRUE(has_rule(f, "read-only"));
}

TEST(ProfileValidate, HandMadeProfilesWithCollisionsAreFindingsNotExceptions) {
  Profile p;
  p.name = "hand-made";
  p.source = "code";
  p.settings = {{"NVKQP", 50, Memory::Both, 0}, {"KQP", 50, std::nullopt, 0}};
  const auto f = validate(p, db());
  EXPECT_TRUE(has_rule(f, "duplicate", Severity::Error)) << dump(f);
}

TEST(ProfileValidate, HandMadeProfilesWithUnknownNamesAreFindings) {
  Profile p;
  p.name = "hand-made";
  p.source = "code";
  p.settings = {{"NVBRAKEON", 19000, std::nullopt, 0}};
  EXPECT_TRUE(has_rule(validate(p, db()), "unknown-parameter", Severity::Error));
}
