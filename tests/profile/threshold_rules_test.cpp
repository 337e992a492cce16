// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 20, item 4: every voltage threshold judged against the bus the card measures, working
// and NV alike, and every threshold pair kept in order, on both sides of each line.
#include <gtest/gtest.h>

#include "profile/plan.hpp"
#include "profile/validate.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

namespace {

std::vector<Finding> at_bus(const std::string& lines, double bus_v, const RawValues* card = nullptr,
                            bool force = false) {
  return validate(load(with_params(lines)), db(), {card, force, bus_v});
}

const Finding* find_rule(const std::vector<Finding>& findings, const std::string& rule) {
  for (const auto& f : findings)
    if (f.rule == rule) return &f;
  return nullptr;
}

// One count of 10 mV above and below a voltage, in the raw counts of the thresholds.
std::int64_t counts(double volts) {
  return static_cast<std::int64_t>(volts * 100 + 0.5);
}

}  // namespace

// Manual, FAULT CONDITIONS: BUSLOVFAULT "Low motor voltage fault". A threshold at or above
// the bus faults the card: the working cell at once, the NV cell from the next reset.
TEST(ThresholdRules, UnderVoltageAtOrAboveTheMeasuredBusIsAnError) {
  auto f = at_bus("  NVBUSUNDERV: 170 V\n", 160);  // the reproduction
  const Finding* nv = find_rule(f, "bus-measured-undervoltage");
  ASSERT_NE(nv, nullptr) << dump(f);
  EXPECT_EQ(nv->severity, Severity::Error);
  EXPECT_EQ(nv->key, "NVBUSUNDERV");
  EXPECT_EQ(nv->where, "test.yaml:3");
  EXPECT_NE(nv->message.find("from the next reset on"), std::string::npos) << nv->message;
  f = at_bus("  BUSUNDERV: 170 V\n", 160);
  const Finding* working = find_rule(f, "bus-measured-undervoltage");
  ASSERT_NE(working, nullptr) << dump(f);
  EXPECT_NE(working->message.find("at once"), std::string::npos) << working->message;
  EXPECT_TRUE(has_rule(at_bus("  BUSUNDERV: 160 V\n", 160), "bus-measured-undervoltage", Severity::Error))
      << "at the bus";
  EXPECT_FALSE(has_rule(at_bus("  BUSUNDERV: 159.99 V\n", 160), "bus-measured-undervoltage"));
  EXPECT_TRUE(has_rule(at_bus("  BUSUNDERV: 170 V\n", 160, nullptr, true), "bus-measured-undervoltage",
                       Severity::Warning))
      << "--force makes it a warning";
}

// The finding says what happened; forcing, which overrides it, is a marker the app names.
TEST(ThresholdRules, AMeasuredBusFindingMarksForceAndNamesNoOption) {
  auto f = at_bus("  BUSUNDERV: 170 V\n", 160);
  const Finding* refused = find_rule(f, "bus-measured-undervoltage");
  ASSERT_NE(refused, nullptr) << dump(f);
  EXPECT_EQ(refused->advice, i20::Advice::Force);
  EXPECT_EQ(refused->message.find("--"), std::string::npos) << refused->message;
  EXPECT_NE(refused->message.find("unless the supply will change first"), std::string::npos)
      << refused->message;
  f = at_bus("  BUSUNDERV: 170 V\n", 160, nullptr, true);
  const Finding* forced = find_rule(f, "bus-measured-undervoltage");
  ASSERT_NE(forced, nullptr) << dump(f);
  EXPECT_EQ(forced->advice, i20::Advice::None) << "forced: nothing left to override";
  EXPECT_NE(forced->message.find("(forced)"), std::string::npos) << forced->message;
}

// Manual, BRAKEONV and BRAKEOFFV: the brake switches on above BRAKEONV and off below
// BRAKEOFFV. Off at or below the supply: after one braking event it never switches off.
TEST(ThresholdRules, BrakeOffAtOrBelowTheMeasuredBusIsAnError) {
  auto f = at_bus("  NVBRAKEONV: 190 V\n  NVBRAKEOFFV: 170 V\n", 180);  // the reproduction
  const Finding* off = find_rule(f, "bus-measured-brake-off");
  ASSERT_NE(off, nullptr) << dump(f);
  EXPECT_EQ(off->severity, Severity::Error);
  EXPECT_EQ(off->key, "NVBRAKEOFFV");
  EXPECT_EQ(off->where, "test.yaml:4");
  EXPECT_FALSE(has_rule(f, "bus-measured-brake")) << "the brake-on is above the bus: " << dump(f);
  EXPECT_TRUE(has_rule(at_bus("  BRAKEONV: 200 V\n  BRAKEOFFV: 180 V\n", 180), "bus-measured-brake-off",
                       Severity::Error));
  f = at_bus("  BRAKEONV: 200 V\n  BRAKEOFFV: 180.01 V\n", 180);
  EXPECT_FALSE(has_rule(f, "bus-measured-brake-off")) << dump(f);
}

// Every threshold, working and NV, on both sides of its line: the siblings, not one example.
TEST(ThresholdRules, EveryThresholdOfBothSpacesAgainstTheMeasuredBus) {
  struct Case {
    const char* base;
    bool unsafe_at_or_below;
    const char* rule;
  };
  const Case cases[] = {
      {"BUSOVERV", true, "bus-measured-overvoltage"},
      {"BRAKEONV", true, "bus-measured-brake"},
      {"BRAKEOFFV", true, "bus-measured-brake-off"},
      {"BUSUNDERV", false, "bus-measured-undervoltage"},
      {"BUSUNDERVMAX", false, "bus-measured-undervoltage-max"},
  };
  const double bus = 170;
  for (const auto& c : cases)
    for (const std::string& cell : {std::string(c.base), "NV" + std::string(c.base)}) {
      SCOPED_TRACE(cell);
      const std::int64_t unsafe_side = c.unsafe_at_or_below ? counts(bus) - 1 : counts(bus) + 1;
      const std::int64_t safe_side = c.unsafe_at_or_below ? counts(bus) + 1 : counts(bus) - 1;
      for (const std::int64_t raw : {unsafe_side, counts(bus)}) {
        const auto f = measured_bus_findings({{cell, raw}}, bus, db(), false);
        ASSERT_EQ(f.size(), 1u) << raw;
        EXPECT_EQ(f[0].rule, c.rule);
        EXPECT_EQ(f[0].key, cell);
        EXPECT_EQ(f[0].severity, Severity::Error);
        EXPECT_NE(f[0].message.find(cell.starts_with("NV") ? "from the next reset on" : "at once"),
                  std::string::npos)
            << f[0].message;
        const auto forced = measured_bus_findings({{cell, raw}}, bus, db(), true);
        ASSERT_EQ(forced.size(), 1u);
        EXPECT_EQ(forced[0].severity, Severity::Warning);
      }
      EXPECT_TRUE(measured_bus_findings({{cell, safe_side}}, bus, db(), false).empty()) << safe_side;
    }
  // Cells that are not thresholds are not judged.
  EXPECT_TRUE(measured_bus_findings({{"NVMAXCURRENT", 100}, {"NVKQP", 1}}, bus, db(), false).empty());
}

// The rules judge what the profile writes; a card's own values are not this profile's.
TEST(ThresholdRules, OnlyThresholdsTheProfileWritesAreJudged) {
  const RawValues card{{"NVBUSUNDERV", counts(200)}, {"NVBRAKEOFFV", counts(100)}};
  const auto f = at_bus("  NVKQP: 50\n  NVKDP: 50\n", 160, &card);
  EXPECT_TRUE(f.empty()) << dump(f);
}

// docs/facts.md s2: the EEPROM's two under-voltage thresholds, NVBUSUNDERV (LinuxCNC's
// nvbusundervmin) and NVBUSUNDERVMAX (nvbusundervmax); the low one stays below the high one.
TEST(ThresholdRules, TheUnderVoltagePairIsKeptInOrder) {
  const auto check = [](const std::string& lines, const RawValues* card = nullptr) {
    return validate(load(with_params(lines)), db(), {card, false, std::nullopt});
  };
  EXPECT_TRUE(check("  NVBUSUNDERV: 90 V\n  NVBUSUNDERVMAX: 100 V\n").empty());
  EXPECT_TRUE(has_rule(check("  NVBUSUNDERV: 100 V\n  NVBUSUNDERVMAX: 100 V\n"), "undervoltage-pair-order",
                       Severity::Error));
  EXPECT_TRUE(has_rule(check("  NVBUSUNDERV: 120 V\n  NVBUSUNDERVMAX: 100 V\n"), "undervoltage-pair-order",
                       Severity::Error));
  EXPECT_TRUE(has_rule(check("  BUSUNDERV: 120 V\n  BUSUNDERVMAX: 100 V\n"), "undervoltage-pair-order",
                       Severity::Error))
      << "the working twins";
  // The shipped line profiles before the fix: NVBUSUNDERV above a card's 40 V NVBUSUNDERVMAX.
  const RawValues card{
      {"NVBUSUNDERV", 3500}, {"NVBUSUNDERVMAX", 4000}, {"BUSUNDERV", 3500}, {"BUSUNDERVMAX", 4000}};
  auto f = check("  NVBUSUNDERV: 90 V\n", &card);
  const Finding* order = find_rule(f, "undervoltage-pair-order");
  ASSERT_NE(order, nullptr) << dump(f);
  EXPECT_EQ(order->key, "NVBUSUNDERV");
  EXPECT_NE(order->message.find("NVBUSUNDERVMAX 40.00 V (card)"), std::string::npos) << order->message;
  EXPECT_TRUE(check("  NVBUSUNDERV: 39.99 V\n", &card).empty());
  // A card already inverted is not this profile's doing.
  const RawValues inverted{{"NVBUSUNDERV", 9000}, {"NVBUSUNDERVMAX", 4000}};
  EXPECT_TRUE(check("  NVKQP: 50\n  NVKDP: 50\n", &inverted).empty());
  // Lowering the high one under the card's low one is the same inversion.
  EXPECT_TRUE(has_rule(check("  NVBUSUNDERVMAX: 30 V\n", &card), "undervoltage-pair-order"));
}

// No card, and no published factory NVBUSUNDERVMAX: raising NVBUSUNDERV alone cannot be judged.
TEST(ThresholdRules, RaisingTheLowUnderVoltageAloneNeedsTheHighOne) {
  const auto offline = [](const std::string& lines) {
    return validate(load(with_params(lines)), db(), {nullptr, false, std::nullopt});
  };
  auto f = offline("  NVBUSUNDERV: 90 V\n");
  const Finding* unknown = find_rule(f, "undervoltage-pair-unknown");
  ASSERT_NE(unknown, nullptr) << dump(f);
  EXPECT_EQ(unknown->severity, Severity::Error);
  EXPECT_NE(unknown->message.find("NVBUSUNDERVMAX"), std::string::npos) << unknown->message;
  EXPECT_TRUE(has_rule(offline("  BUSUNDERV: 90 V\n"), "undervoltage-pair-unknown"));
  EXPECT_TRUE(offline("  NVBUSUNDERV: 35 V\n").empty()) << "the factory value";
  EXPECT_TRUE(offline("  NVBUSUNDERV: 24 V\n").empty()) << "lowered: still below the factory high one";
  EXPECT_TRUE(offline("  NVBUSUNDERV: 90 V\n  NVBUSUNDERVMAX: 100 V\n").empty());
}

TEST(ThresholdRules, TheHighUnderVoltageAgainstTheProfilesSupply) {
  const std::string bus170 = "supply:\n  bus_voltage: 170 V\n";
  auto f = validate(load(with_params("  NVBUSUNDERV: 90 V\n  NVBUSUNDERVMAX: 170 V\n", bus170)), db());
  EXPECT_TRUE(has_rule(f, "bus-above-undervoltage-max", Severity::Error)) << dump(f);
  f = validate(load(with_params("  NVBUSUNDERV: 90 V\n  NVBUSUNDERVMAX: 169.99 V\n", bus170)), db());
  EXPECT_FALSE(has_rule(f, "bus-above-undervoltage-max")) << dump(f);
}

// The write order keeps the pair in order at every step (raised: high one first; lowered:
// low one first), and the step check names an order that would invert it.
TEST(ThresholdRules, TheWriteOrderKeepsTheUnderVoltagePair) {
  const RawValues card{{"NVBUSUNDERV", 3500}, {"NVBUSUNDERVMAX", 4000}};
  const auto up = make_plan(load(with_params("  NVBUSUNDERV: 90 V\n  NVBUSUNDERVMAX: 100 V\n")), db(), card);
  ASSERT_EQ(up.steps.size(), 2u);
  EXPECT_EQ(up.steps[0].cell, "NVBUSUNDERVMAX");
  EXPECT_EQ(unsafe_step(up, db(), card), "");
  const RawValues high{{"NVBUSUNDERV", 9000}, {"NVBUSUNDERVMAX", 10000}};
  const auto down = make_plan(load(with_params("  NVBUSUNDERV: 35 V\n  NVBUSUNDERVMAX: 40 V\n")), db(), high);
  ASSERT_EQ(down.steps.size(), 2u);
  EXPECT_EQ(down.steps[0].cell, "NVBUSUNDERV");
  EXPECT_EQ(unsafe_step(down, db(), high), "");
  Plan wrong = up;
  std::swap(wrong.steps[0], wrong.steps[1]);
  EXPECT_NE(unsafe_step(wrong, db(), card).find("NVBUSUNDERV 90.00 V is not below NVBUSUNDERVMAX 40.00 V"),
            std::string::npos)
      << unsafe_step(wrong, db(), card);
}

// Manual, MOTOR POWER: motor power is 35 to 400 V and communication works down to 0 V. A
// bus below 35 V is a supply that is off (a bench with logic power only): the under-voltage
// thresholds are not judged against it, while the brake and over-voltage ones still are.
TEST(ThresholdRules, AnOffSupplyDoesNotJudgeTheUnderVoltageThresholds) {
  for (const double bus : {0.0, 12.0, 34.9}) {
    EXPECT_TRUE(
        measured_bus_findings({{"NVBUSUNDERV", 3500}, {"BUSUNDERVMAX", 4000}}, bus, db(), false).empty())
        << bus << " V";
    EXPECT_FALSE(measured_bus_findings({{"NVBRAKEOFFV", 100}}, bus + 5, db(), false).empty()) << bus << " V";
  }
  // From the lowest motor supply on, they are judged again.
  EXPECT_FALSE(measured_bus_findings({{"NVBUSUNDERV", 3600}}, 35.0, db(), false).empty());
}
