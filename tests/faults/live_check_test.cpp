// SPDX-License-Identifier: GPL-2.0-or-later
// The fault table's `live_check` blocks: how live readings show a latched FAULT bit's
// cause now. The loader's strictness (one-line "file:line: reason" errors) and the shipped
// table's checks against the manual's FAULT CONDITIONS.
#include <gtest/gtest.h>

#include "faults/fault_table.hpp"
#include "params/param_db.hpp"
#include "table_yaml.hpp"

using namespace i20::faults;
using namespace i20::faults::testing;

namespace {

// FAULT bit 1 carries `check` ("live_check:" is line 15, its first key line 16); STATUS has
// bits 3 and 8 (STATUS bit 8's `status_extra` starts at line 52).
std::string with_check(const std::string& check, const std::string& status_extra = "") {
  return "schema: 1\ndevice: 8I20\nfault:\n" + bit(1, "one", "    live_check:\n" + check) + bit(2, "two") +
         "status:\n" + bit(3, "status-three") + bit(8, "status-eight", status_extra);
}

const LiveCheck& check_of(const FaultTable& t, unsigned fault_bit) {
  const BitInfo* b = t.find(Register::Fault, fault_bit);
  if (!b || !b->live_check)
    throw std::runtime_error("FAULT bit " + std::to_string(fault_bit) + " has no live_check");
  return *b->live_check;
}

}  // namespace

TEST(FaultLiveCheck, ReadsAMeasurementAgainstAParameter) {
  const auto t = FaultTable::load_string(
      with_check(
          "      measured: BUSV\n      below: BUSUNDERV\n      unit: V\n      advice: raise the supply\n"),
      "ok.yaml");
  const LiveCheck& c = check_of(t, 1);
  EXPECT_EQ(c.measured, "BUSV");
  EXPECT_EQ(c.compare, LiveCheck::Compare::Below);
  EXPECT_EQ(c.threshold_param, "BUSUNDERV");
  EXPECT_FALSE(c.threshold_value);
  EXPECT_FALSE(c.fixed);
  EXPECT_EQ(c.unit, "V");
  EXPECT_EQ(c.advice, "raise the supply");
  EXPECT_FALSE(c.status_bit);
  EXPECT_EQ(c.origin, "ok.yaml:16");  // the block's first key
  EXPECT_FALSE(t.find(Register::Fault, 2u)->live_check) << "the block is optional";
}

TEST(FaultLiveCheck, ReadsAFixedNumericLimit) {
  const auto t = FaultTable::load_string(
      with_check("      measured: TEMPERATURE\n      above: 85.5\n      fixed: true\n      unit: degC\n"),
      "ok.yaml");
  const LiveCheck& c = check_of(t, 1);
  EXPECT_EQ(c.compare, LiveCheck::Compare::Above);
  ASSERT_TRUE(c.threshold_value);
  EXPECT_DOUBLE_EQ(*c.threshold_value, 85.5);
  EXPECT_TRUE(c.threshold_param.empty());
  EXPECT_TRUE(c.fixed);
  EXPECT_DOUBLE_EQ(t.fixed_limit("one"), 85.5);
  EXPECT_DOUBLE_EQ(t.fixed_limit("1"), 85.5);
}

TEST(FaultLiveCheck, FixedLimitThrowsWithoutANumber) {
  const auto t = FaultTable::load_string(
      with_check("      measured: BUSV\n      above: BUSOVERV\n      unit: V\n"), "ok.yaml");
  EXPECT_THROW(t.fixed_limit("one"), FaultFileError) << "a parameter threshold is no fixed limit";
  EXPECT_THROW(t.fixed_limit("two"), FaultFileError) << "no live_check at all";
  EXPECT_THROW(t.fixed_limit("nonesuch"), FaultFileError);
}

TEST(FaultLiveCheck, ResolvesTheStatusBitBySlug) {
  const auto t = FaultTable::load_string(
      with_check("      status: status-eight\n      status_set: not driven\n      status_clear: driven\n"),
      "ok.yaml");
  const LiveCheck& c = check_of(t, 1);
  EXPECT_TRUE(c.measured.empty());
  ASSERT_TRUE(c.status_bit);
  EXPECT_EQ(*c.status_bit, 8u);
  EXPECT_EQ(c.status_set, "not driven");
  EXPECT_EQ(c.status_clear, "driven");
}

TEST(FaultLiveCheck, RejectsAStatusSlugThatNamesNoStatusBit) {
  EXPECT_TRUE(rejected_at(with_check("      status: status-nine\n      status_set: x\n"), 16,
                          "names no STATUS bit: 'status-nine'"));
  // A FAULT bit's slug is not a STATUS bit.
  EXPECT_TRUE(
      rejected_at(with_check("      status: two\n      status_set: x\n"), 16, "names no STATUS bit: 'two'"));
}

TEST(FaultLiveCheck, RejectsBadShapes) {
  EXPECT_TRUE(rejected_at(with_check("      unit: V\n"), 16, "needs 'measured'"));  // `unit` without measured
  EXPECT_TRUE(rejected_at(with_check("      status: status-eight\n      status_set: x\n      advice: x\n"),
                          18, "'advice' needs 'measured'"));
  EXPECT_TRUE(
      rejected_at(with_check("      measured: BUSV\n      above: 4\n      unit: V\n      status_set: x\n"),
                  19, "'status_set' needs 'status'"));
  EXPECT_TRUE(rejected_at(with_check("      measured: BUSV\n      unit: V\n"), 16,
                          "exactly one of 'above' and 'below'"));
  EXPECT_TRUE(rejected_at(with_check("      measured: BUSV\n      above: 1\n      below: 2\n      unit: V\n"),
                          16, "exactly one of 'above' and 'below'"));
  EXPECT_TRUE(
      rejected_at(with_check("      measured: BUSV\n      above: 400\n"), 16, "lacks required key 'unit'"));
  EXPECT_TRUE(rejected_at(with_check("      status: status-eight\n"), 16, "lacks required key 'status_set'"));
  EXPECT_TRUE(
      rejected_at(with_check("      measured: BUSV\n      above: 400\n      unit: V\n      limit: 3\n"), 19,
                  "unknown key 'limit'"));
  EXPECT_TRUE(
      rejected_at(with_check("      measured: BUSV\n      measured: BUSV\n      above: 4\n      unit: V\n"),
                  17, "key 'measured' given twice"));
  EXPECT_TRUE(rejected_at(
      "schema: 1\nfault:\n" + bit(1, "one", "    live_check: [BUSV]\n") + "status:\n" + bit(0, "status-zero"),
      14, "'live_check' must be a map"));
}

TEST(FaultLiveCheck, RejectsBadValues) {
  EXPECT_TRUE(rejected_at(with_check("      measured: bus v\n      above: 4\n      unit: V\n"), 16,
                          "'measured' must be a parameter name"));
  EXPECT_TRUE(rejected_at(with_check("      measured: BUSV\n      above: 400 V\n      unit: V\n"), 17,
                          "'above' must be a parameter name like BUSOVERV or a number, not '400 V'"));
  EXPECT_TRUE(rejected_at(with_check("      measured: BUSV\n      below: nan\n      unit: V\n"), 17,
                          "'below' must be a parameter name"));
  EXPECT_TRUE(rejected_at(
      with_check("      measured: BUSV\n      above: BUSOVERV\n      fixed: true\n      unit: V\n"), 18,
      "'fixed: true' is for a number"));
  EXPECT_TRUE(
      rejected_at(with_check("      measured: BUSV\n      above: 400\n      fixed: yes\n      unit: V\n"), 18,
                  "'fixed' must be true or false"));
  EXPECT_TRUE(rejected_at(with_check("      measured: BUSV\n      above: 400\n      unit: \"\"\n"), 18,
                          "'unit' must be a non-empty text"));
}

TEST(FaultLiveCheck, IsForFaultBitsOnly) {
  EXPECT_TRUE(
      rejected_at(with_check("      status: status-eight\n      status_set: x\n",
                             "    live_check:\n      measured: BUSV\n      above: 4\n      unit: V\n"),
                  53, "'live_check' is for FAULT bits"));
}

// The shipped table against the manual's FAULT CONDITIONS (bit numbers and limits) and,
// for the STATUS bits the manual does not define, LinuxCNC's names (docs/facts.md s4).
TEST(FaultLiveCheckBuiltin, FollowsTheManualsFaultConditions) {
  const auto& t = FaultTable::builtin();
  const LiveCheck& enable = check_of(t, 1);  // NOENABLEFAULT 1
  EXPECT_EQ(t.find(Register::Fault, 1u)->name, "NOENABLEFAULT");
  ASSERT_TRUE(enable.status_bit);
  EXPECT_EQ(*enable.status_bit, 8u);  // NOENABLESTATUS (LinuxCNC status.no-enable)
  EXPECT_FALSE(enable.status_clear.empty());

  const LiveCheck& temp = check_of(t, 2);  // OVERTEMPFAULT 2: PCB temperature > 85C
  EXPECT_EQ(t.find(Register::Fault, 2u)->name, "OVERTEMPFAULT");
  EXPECT_EQ(temp.measured, "TEMPERATURE");
  EXPECT_EQ(temp.compare, LiveCheck::Compare::Above);
  ASSERT_TRUE(temp.threshold_value);
  EXPECT_DOUBLE_EQ(*temp.threshold_value, 85.0);

  const LiveCheck& low = check_of(t, 8);  // BUSLOVFAULT 8
  EXPECT_EQ(t.find(Register::Fault, 8u)->name, "BUSLOVFAULT");
  EXPECT_EQ(low.measured, "BUSV");
  EXPECT_EQ(low.compare, LiveCheck::Compare::Below);
  EXPECT_EQ(low.threshold_param, "BUSUNDERV");
  ASSERT_TRUE(low.status_bit);
  EXPECT_EQ(*low.status_bit, 3u);  // LinuxCNC status.bus-underv
  EXPECT_TRUE(low.status_clear.empty()) << "a clear STATUS bit 3 is not trusted to show the supply fine";

  const LiveCheck& high = check_of(t, 9);  // BUSHIVFAULT 9 (settable)
  EXPECT_EQ(t.find(Register::Fault, 9u)->name, "BUSHIVFAULT");
  EXPECT_EQ(high.measured, "BUSV");
  EXPECT_EQ(high.compare, LiveCheck::Compare::Above);
  EXPECT_EQ(high.threshold_param, "BUSOVERV");

  const LiveCheck& max = check_of(t, 10);  // MAXBUSVFAULT 10 (fixed at 400V)
  EXPECT_EQ(t.find(Register::Fault, 10u)->name, "MAXBUSVFAULT");
  EXPECT_EQ(max.measured, "BUSV");
  EXPECT_EQ(max.compare, LiveCheck::Compare::Above);
  EXPECT_TRUE(max.fixed);
  EXPECT_DOUBLE_EQ(t.fixed_limit("max-bus-voltage"), 400.0);

  // Events only the card can tell: watchdog, over-current, phase currents, module, serial.
  for (unsigned b : {0u, 4u, 5u, 6u, 7u, 11u, 14u, 15u})
    EXPECT_FALSE(t.find(Register::Fault, b)->live_check) << b;
}

// Every reading and threshold a live check names is a parameter of the database, in the
// unit the check quotes: a typo (BUSVV) or a unit slip would make the check silently unknown.
TEST(FaultLiveCheckBuiltin, NamesDatabaseParametersInTheirUnits) {
  const auto db = i20::params::ParamDb::builtin();
  int checked = 0;
  for (const auto& b : FaultTable::builtin().bits(Register::Fault)) {
    if (!b.live_check || b.live_check->measured.empty()) continue;
    SCOPED_TRACE(b.name);
    const auto& c = *b.live_check;
    for (const auto& name : {c.measured, c.threshold_param}) {
      if (name.empty()) continue;
      const auto* p = db.find(name);
      ASSERT_NE(p, nullptr) << name;
      EXPECT_EQ(p->unit, c.unit) << name;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 6);  // TEMPERATURE; BUSV+BUSUNDERV; BUSV+BUSOVERV; BUSV
}
