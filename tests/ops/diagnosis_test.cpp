// SPDX-License-Identifier: GPL-2.0-or-later
// ops::cause_now: whether a latched FAULT bit's cause is there now, per bit, from live
// readings. Bit numbers are the manual's FAULT CONDITIONS table (NOENABLEFAULT 1,
// OVERTEMPFAULT 2 "PCB temperature > 85C", BUSLOVFAULT 8, BUSHIVFAULT 9 "settable",
// MAXBUSVFAULT 10 "fixed at 400V"); STATUS bits 3 and 8 are LinuxCNC's (docs/facts.md s4).
// The evidence texts are what `i20 faults` prints (tests/cli_faults checks them there too).
#include "ops/diagnosis.hpp"

#include <gtest/gtest.h>

using i20::ops::cause_now;
using i20::ops::CauseNow;
using i20::ops::FaultReadings;

namespace {

constexpr unsigned kNoEnable = 1, kOverTemp = 2, kBusLow = 8, kBusHigh = 9, kBusMax = 10;
constexpr std::uint16_t kStatusBusUnderV = 1u << 3, kStatusNoEnable = 1u << 8;

// A card with everything read: 320 V bus, thresholds at the manual's defaults, 40 degC.
FaultReadings healthy() {
  FaultReadings r;
  r.busv_v = 320.0;
  r.temperature_c = 40.0;
  r.busunderv_v = 35.0;
  r.busoverv_v = 385.0;
  r.brakeonv_v = 360.0;
  return r;
}

::testing::AssertionResult is(const CauseNow& c, CauseNow::State state, const std::string& evidence) {
  if (c.state == state && c.evidence == evidence) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "got state " << c.state << " '" << c.evidence << "', expected "
                                       << state << " '" << evidence << "'";
}

}  // namespace

TEST(OpsDiagnosis, NoEnableFollowsStatusBit8BothWays) {
  auto r = healthy();
  r.status = kStatusNoEnable;
  EXPECT_TRUE(is(cause_now(kNoEnable, r), CauseNow::Present,
                 "the enable input (TB1 pins 3-4) is not driven now (STATUS bit 8)"));
  r.status = static_cast<std::uint16_t>(~kStatusNoEnable);  // every other bit set: only bit 8 counts
  EXPECT_TRUE(
      is(cause_now(kNoEnable, r), CauseNow::Gone, "the enable input is driven now (STATUS bit 8 clear)"));
}

TEST(OpsDiagnosis, OverTemperatureIsAbove85C) {
  auto r = healthy();
  r.temperature_c = 90.0;
  EXPECT_TRUE(is(cause_now(kOverTemp, r), CauseNow::Present,
                 "TEMPERATURE is 90.00 degC, above the 85 degC limit: let the card cool"));
  r.temperature_c = 85.0;  // "> 85C": at the limit the cause is gone
  EXPECT_TRUE(
      is(cause_now(kOverTemp, r), CauseNow::Gone, "TEMPERATURE is 85.00 degC, below the 85 degC limit"));
  r.temperature_c.reset();
  EXPECT_TRUE(is(cause_now(kOverTemp, r), CauseNow::Unknown, ""));
}

TEST(OpsDiagnosis, BusUnderVoltageIsBusvBelowBusunderv) {
  auto r = healthy();
  r.busv_v = 24.0;
  EXPECT_TRUE(
      is(cause_now(kBusLow, r), CauseNow::Present,
         "BUSV is 24.00 V, below BUSUNDERV 35.00 V: motor supply off or low, or BUSUNDERV set too high"));
  r.busv_v = 35.0;
  EXPECT_TRUE(is(cause_now(kBusLow, r), CauseNow::Gone, "BUSV is 35.00 V, above BUSUNDERV 35.00 V"));
  // The readings decide even against STATUS bit 3.
  r.status = kStatusBusUnderV;
  EXPECT_EQ(cause_now(kBusLow, r).state, CauseNow::Gone);
}

TEST(OpsDiagnosis, BusUnderVoltageFallsBackOnStatusBit3OnlyToShowItPresent) {
  auto r = healthy();
  r.busunderv_v.reset();  // threshold not read (address not confirmed)
  r.busv_v = 24.0;
  EXPECT_TRUE(is(cause_now(kBusLow, r), CauseNow::Unknown, "")) << "STATUS bit 3 clear proves nothing";
  r.status = kStatusBusUnderV;
  EXPECT_TRUE(
      is(cause_now(kBusLow, r), CauseNow::Present, "the motor supply is under-voltage now (STATUS bit 3)"));
  r = healthy();
  r.busv_v.reset();
  r.status = kStatusBusUnderV;
  EXPECT_EQ(cause_now(kBusLow, r).state, CauseNow::Present);
  r.status = kStatusNoEnable;  // another STATUS bit does not count
  EXPECT_EQ(cause_now(kBusLow, r).state, CauseNow::Unknown);
}

TEST(OpsDiagnosis, BusOverVoltageIsBusvAboveTheSettableBusoverv) {
  auto r = healthy();
  r.busv_v = 390.0;
  EXPECT_TRUE(is(cause_now(kBusHigh, r), CauseNow::Present, "BUSV is 390.00 V, above BUSOVERV 385.00 V"));
  r.busoverv_v = 395.0;  // settable: the card's threshold, not a constant
  EXPECT_TRUE(is(cause_now(kBusHigh, r), CauseNow::Gone, "BUSV is 390.00 V, below BUSOVERV 395.00 V"));
  r.busoverv_v.reset();
  EXPECT_EQ(cause_now(kBusHigh, r).state, CauseNow::Unknown);
  r = healthy();
  r.busv_v.reset();
  EXPECT_EQ(cause_now(kBusHigh, r).state, CauseNow::Unknown);
}

TEST(OpsDiagnosis, MaxBusVoltageIsBusvAboveTheFixed400V) {
  auto r = healthy();
  r.busv_v = 410.0;
  r.busoverv_v = 450.0;  // the fixed limit does not move with BUSOVERV
  EXPECT_TRUE(is(cause_now(kBusMax, r), CauseNow::Present, "BUSV is 410.00 V, above the fixed 400 V limit"));
  r.busv_v = 400.0;
  EXPECT_TRUE(is(cause_now(kBusMax, r), CauseNow::Gone, "BUSV is 400.00 V, below the fixed 400 V limit"));
  r.busv_v.reset();
  EXPECT_EQ(cause_now(kBusMax, r).state, CauseNow::Unknown);
}

TEST(OpsDiagnosis, EventsAndReservedBitsAreUnknownWhateverTheReadings) {
  auto r = healthy();
  r.status = 0xFFFF;
  r.busv_v = 500.0;
  r.temperature_c = 120.0;
  // Watchdog, over-current, U/V/W current, module, serial overrun and framing: events only
  // the card can tell; 3, 12, 13 reserved; 16 outside the register.
  for (unsigned b : {0u, 4u, 5u, 6u, 7u, 11u, 14u, 15u, 3u, 12u, 13u, 16u})
    EXPECT_TRUE(is(cause_now(b, r), CauseNow::Unknown, "")) << "bit " << b;
}

// The decision is the table's: another table's check (here: bit 4 against a 50 degC
// temperature limit, bit 2 with no check) changes the answer without code.
TEST(OpsDiagnosis, FollowsTheTablesLiveChecks) {
  auto entry = [](unsigned n, const std::string& name, const std::string& extra) {
    return "  - bit: " + std::to_string(n) + "\n    name: " + name + "\n    slug: s" + std::to_string(n) +
           "\n    severity: fault\n    meaning: m\n    causes: [c]\n    checks: [k]\n    sticky: true\n"
           "    maskable: false\n    clears_while_cause_persists: false\n    source: test\n" +
           extra;
  };
  const auto table = i20::faults::FaultTable::load_string(
      "schema: 1\nfault:\n" + entry(2, "TWO", "") +
          entry(4, "FOUR",
                "    live_check:\n      measured: TEMPERATURE\n      below: 50\n      unit: degC\n"
                "      status: s7\n      status_set: cold\n") +
          "status:\n" + entry(7, "SEVEN", ""),
      "test.yaml");
  auto r = healthy();
  r.temperature_c = 40.0;
  EXPECT_TRUE(
      is(cause_now(4, r, table), CauseNow::Present, "TEMPERATURE is 40.00 degC, below the 50 degC limit"));
  r.temperature_c = 90.0;
  EXPECT_TRUE(
      is(cause_now(4, r, table), CauseNow::Gone, "TEMPERATURE is 90.00 degC, above the 50 degC limit"));
  EXPECT_EQ(cause_now(2, r, table).state, CauseNow::Unknown);
  r.temperature_c.reset();
  r.status = 1u << 7;
  EXPECT_TRUE(is(cause_now(4, r, table), CauseNow::Present, "cold (STATUS bit 7)"));
  r.status = 0;
  EXPECT_EQ(cause_now(4, r, table).state, CauseNow::Unknown);
}

TEST(OpsDiagnosis, LiveValuesNameOnlyTheReadingsTaken) {
  FaultReadings r;
  r.busv_v = 320.0;
  r.brakeonv_v = 360.0;
  const auto live = i20::ops::live_values(r);
  ASSERT_EQ(live.size(), 2u);
  EXPECT_DOUBLE_EQ(live.at("BUSV"), 320.0);
  EXPECT_DOUBLE_EQ(live.at("BRAKEONV"), 360.0);
}
