// SPDX-License-Identifier: GPL-2.0-or-later
// Decoding FAULT and STATUS against the manual's tables (FAULT CONDITIONS, STATUS REGISTER)
// and docs/facts.md s4.
#include "faults/decode.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

using namespace i20::faults;

namespace {

struct Expected {
  unsigned bit;
  const char* name;
  const char* slug;
};

// The manual's FAULT CONDITIONS table, verbatim names.
constexpr Expected kFaultBits[] = {
    {0, "WATCHDOGFAULT", "watchdog"},
    {1, "NOENABLEFAULT", "no-enable"},
    {2, "OVERTEMPFAULT", "over-temperature"},
    {4, "CURRENTFAULT", "over-current"},
    {5, "ULOOPCURRENTFAULT", "u-current"},
    {6, "VLOOPCURRENTFAULT", "v-current"},
    {7, "WLOOPCURRENTFAULT", "w-current"},
    {8, "BUSLOVFAULT", "bus-under-voltage"},
    {9, "BUSHIVFAULT", "bus-over-voltage"},
    {10, "MAXBUSVFAULT", "max-bus-voltage"},
    {11, "MODULEFAULT", "module"},
    {14, "OERRFAULT", "serial-overrun"},
    {15, "FERRFAULT", "serial-framing"},
};

// The manual's STATUS REGISTER table.
constexpr Expected kStatusBits[] = {
    {0, "ILIMITEDSTATUS", "current-limited"},
    {1, "BRAKESTATUS", "brake-on"},
    {2, "BRAKEWASONSTATUS", "brake-was-on"},
    {4, "WDTO", "dsp-watchdog-reset"},
    {5, "SWR", "software-reset"},
    {6, "EXTR", "external-reset"},
};

std::string joined(const std::vector<std::string>& texts) {
  std::string out;
  for (const auto& t : texts) out += t + "\n";
  return out;
}

const BitInfo& fault_bit(unsigned bit) {
  return *FaultTable::builtin().find(Register::Fault, bit);
}

}  // namespace

TEST(FaultDecode, EveryManualBitAloneDecodesToItsNameAndNumber) {
  for (const auto& e : kFaultBits) {
    SCOPED_TRACE(e.name);
    const auto d = decode_fault(static_cast<std::uint16_t>(1u << e.bit));
    ASSERT_EQ(d.bits.size(), 1u);
    EXPECT_EQ(d.bits[0].bit, e.bit);
    ASSERT_FALSE(d.bits[0].reserved());
    EXPECT_EQ(d.bits[0].info->name, e.name);
    EXPECT_EQ(d.bits[0].info->slug, e.slug);
    EXPECT_EQ(d.bits[0].info->reg, Register::Fault);
    EXPECT_EQ(d.bits[0].label(), e.name);
    EXPECT_EQ(d.reserved, 0);
  }
}

TEST(FaultDecode, TableHoldsExactlyTheManualBits) {
  EXPECT_EQ(FaultTable::builtin().defined_bits(Register::Fault), 0xCFF7);  // all but 3, 12, 13
  EXPECT_EQ(FaultTable::builtin().bits(Register::Fault).size(), std::size(kFaultBits));
}

TEST(StatusDecode, EveryManualBitAloneDecodesToItsNameAndNumber) {
  for (const auto& e : kStatusBits) {
    SCOPED_TRACE(e.name);
    const auto d = decode_status(static_cast<std::uint16_t>(1u << e.bit));
    ASSERT_EQ(d.bits.size(), 1u);
    EXPECT_EQ(d.bits[0].bit, e.bit);
    ASSERT_FALSE(d.bits[0].reserved());
    EXPECT_EQ(d.bits[0].info->name, e.name);
    EXPECT_EQ(d.bits[0].info->slug, e.slug);
    EXPECT_EQ(d.bits[0].info->reg, Register::Status);
    EXPECT_EQ(d.bits[0].info->source.find("LinuxCNC"), std::string::npos);
  }
}

TEST(StatusDecode, LinuxCncBitsAreDecodedAndMarkedWithTheirSource) {
  // docs/facts.md s4: LinuxCNC names bit 3 bus under-voltage, 8 no enable, 9 current loop on.
  const std::pair<unsigned, const char*> linuxcnc[] = {
      {3, "status.bus-underv"}, {8, "status.no-enable"}, {9, "status.pid-on"}};
  for (const auto& [bit, pin] : linuxcnc) {
    SCOPED_TRACE(pin);
    const auto d = decode_status(static_cast<std::uint16_t>(1u << bit));
    ASSERT_EQ(d.bits.size(), 1u);
    ASSERT_FALSE(d.bits[0].reserved());
    EXPECT_EQ(d.bits[0].info->linuxcnc_pin, pin);
    EXPECT_NE(d.bits[0].info->source.find("LinuxCNC"), std::string::npos);
    EXPECT_NE(d.bits[0].info->source.find("not in the 8I20 manual"), std::string::npos);
  }
  EXPECT_EQ(FaultTable::builtin().defined_bits(Register::Status), 0x037F);
}

TEST(StatusDecode, StickyBitsAreThoseTheManualMarksSticky) {
  for (const auto& b : FaultTable::builtin().bits(Register::Status)) {
    SCOPED_TRACE(b.name);
    const bool manual_sticky = b.bit == 2 || b.bit == 4 || b.bit == 5 || b.bit == 6;
    EXPECT_EQ(b.sticky, manual_sticky);
    EXPECT_FALSE(b.maskable);
  }
}

TEST(FaultDecode, FaultsLatchUntilClearfaultAndOnlyBusUnderVoltageIsMaskable) {
  for (const auto& b : FaultTable::builtin().bits(Register::Fault)) {
    SCOPED_TRACE(b.name);
    EXPECT_TRUE(b.sticky);
    EXPECT_EQ(b.maskable, b.bit == 8);
    EXPECT_EQ(b.severity, Impact::Fault);
  }
  EXPECT_EQ(FaultTable::builtin().maskable_bits(), 0x0100);
}

TEST(FaultDecode, LevelConditionsDoNotClearWhileTheirCausePersists) {
  for (unsigned bit : {1u, 2u, 8u, 9u, 10u, 11u})
    EXPECT_FALSE(fault_bit(bit).clears_while_cause_persists) << bit;
  for (unsigned bit : {0u, 4u, 5u, 6u, 7u, 14u, 15u})
    EXPECT_TRUE(fault_bit(bit).clears_while_cause_persists) << bit;
}

TEST(FaultDecode, NoEnableAndBusUnderVoltageTogether) {
  const auto d = decode_fault(0x0102);
  ASSERT_EQ(d.bits.size(), 2u);
  EXPECT_EQ(d.bits[0].info->slug, "no-enable");
  EXPECT_EQ(d.bits[1].info->slug, "bus-under-voltage");
  EXPECT_EQ(d.value, 0x0102);
  EXPECT_EQ(d.reg, Register::Fault);
}

TEST(FaultDecode, SetBitsComeLowestFirst) {
  const auto d = decode_fault(0xC011);
  std::vector<unsigned> bits;
  for (const auto& b : d.bits) bits.push_back(b.bit);
  EXPECT_EQ(bits, (std::vector<unsigned>{0, 4, 14, 15}));
}

TEST(FaultDecode, ZeroMeansNothingSet) {
  EXPECT_TRUE(decode_fault(0).empty());
  EXPECT_TRUE(decode_status(0).empty());
}

TEST(FaultDecode, ReservedBitsAreReportedAsUndocumented) {
  for (unsigned bit : {3u, 12u, 13u}) {
    const auto d = decode_fault(static_cast<std::uint16_t>(1u << bit));
    ASSERT_EQ(d.bits.size(), 1u);
    EXPECT_TRUE(d.bits[0].reserved());
    EXPECT_EQ(d.bits[0].meaning(), "reserved/undocumented bit " + std::to_string(bit) + " set");
    EXPECT_EQ(d.bits[0].label(), "reserved bit " + std::to_string(bit));
    EXPECT_EQ(d.reserved, 1u << bit);
  }
  const auto all = decode_fault(0xFFFF);
  EXPECT_EQ(all.bits.size(), 16u);
  EXPECT_EQ(all.reserved, 0x3008);
}

TEST(StatusDecode, ReservedBitsAreReportedAsUndocumented) {
  for (unsigned bit : {7u, 10u, 11u, 12u, 13u, 14u, 15u}) {
    const auto d = decode_status(static_cast<std::uint16_t>(1u << bit));
    ASSERT_EQ(d.bits.size(), 1u);
    EXPECT_TRUE(d.bits[0].reserved());
    EXPECT_EQ(d.bits[0].meaning(), "reserved/undocumented bit " + std::to_string(bit) + " set");
  }
  EXPECT_EQ(decode_status(0xFFFF).reserved, 0xFC80);
}

TEST(FaultDecode, EveryBitCarriesCausesChecksAndASource) {
  for (auto reg : {Register::Fault, Register::Status})
    for (const auto& b : FaultTable::builtin().bits(reg)) {
      SCOPED_TRACE(b.name);
      EXPECT_FALSE(b.meaning.empty());
      EXPECT_FALSE(b.causes.empty());
      EXPECT_FALSE(b.checks.empty());
      EXPECT_FALSE(b.source.empty());
      EXPECT_FALSE(b.linuxcnc_pin.empty());
    }
}

TEST(FaultDecode, ChecksNameWhatToMeasureOnTheMachine) {
  // The advice the field needs, from the manual's sections.
  const auto has = [](unsigned bit, const std::string& text) {
    const auto& b = fault_bit(bit);
    return joined(b.checks).find(text) != std::string::npos || b.meaning.find(text) != std::string::npos;
  };
  EXPECT_TRUE(has(1, "TB1 pin 3 (+) and pin 4 (-)"));
  EXPECT_TRUE(has(1, "4-24 V"));
  EXPECT_TRUE(has(8, "FAULTMASK"));
  EXPECT_TRUE(has(8, "35 V"));
  EXPECT_TRUE(has(8, "terminals 4 (+) and 5 (-)"));
  EXPECT_TRUE(has(0, "40 ms"));
  EXPECT_TRUE(has(0, "servo thread"));
  EXPECT_TRUE(has(2, "0.77 C/W"));
  EXPECT_TRUE(has(9, "terminals 2 (-) and 3 (+)"));
  EXPECT_TRUE(has(9, "BRAKEONV"));
  EXPECT_TRUE(has(10, "400 V"));
  EXPECT_TRUE(has(5, "MAXCURRENT"));
  EXPECT_TRUE(has(4, "insulation"));
  EXPECT_TRUE(has(11, "CR18"));
  EXPECT_TRUE(has(14, "W4 and W5"));
  EXPECT_TRUE(has(15, "W4 and W5"));
}

TEST(FaultDecode, DecodedBitsOutliveTheTableTheyCameFrom) {
  const char* src = std::getenv("I20_SOURCE_DIR");
  ASSERT_NE(src, nullptr);
  Decoded d;
  {
    const auto table = FaultTable::load_file(std::filesystem::path(src) / "params" / "faults.yaml");
    d = decode_fault(0x0002, table);
  }
  ASSERT_EQ(d.bits.size(), 1u);
  EXPECT_EQ(d.bits[0].info->name, "NOENABLEFAULT");
}

TEST(FaultLookup, FindsBySlugNameOrLinuxCncPinIgnoringCase) {
  const auto& t = FaultTable::builtin();
  for (const char* key :
       {"bus-under-voltage", "BUSLOVFAULT", "buslovfault", "fault.bus-underv", "Bus-Under-Voltage"}) {
    const BitInfo* b = t.find(key);
    ASSERT_NE(b, nullptr) << key;
    EXPECT_EQ(b->bit, 8u);
    EXPECT_EQ(b->reg, Register::Fault);
  }
  ASSERT_NE(t.find("status-no-enable"), nullptr);
  EXPECT_EQ(t.find("status-no-enable")->reg, Register::Status);
  EXPECT_EQ(t.find("nonsense"), nullptr);
  EXPECT_EQ(t.find("8"), nullptr);  // a number needs a register
  ASSERT_NE(t.find(Register::Fault, "8"), nullptr);
  EXPECT_EQ(t.find(Register::Fault, "8")->name, "BUSLOVFAULT");
  EXPECT_EQ(t.find(Register::Status, "no-enable"), nullptr);
}

TEST(FaultLookup, UnknownKeysSuggestTheClosestSlugs) {
  try {
    FaultTable::builtin().get(Register::Fault, "bus-undervoltage");
    FAIL() << "expected UnknownBit";
  } catch (const UnknownBit& e) {
    ASSERT_FALSE(e.suggestions().empty());
    EXPECT_EQ(e.suggestions()[0], "bus-under-voltage");
    EXPECT_NE(std::string(e.what()).find("did you mean bus-under-voltage"), std::string::npos) << e.what();
  }
  try {
    FaultTable::builtin().get(Register::Fault, "3");
    FAIL() << "expected UnknownBit";
  } catch (const UnknownBit& e) {
    EXPECT_NE(std::string(e.what()).find("FAULT bit 3 is reserved"), std::string::npos) << e.what();
  }
  try {
    FaultTable::builtin().get(Register::Fault, "current-loop-on");
    FAIL() << "expected UnknownBit";
  } catch (const UnknownBit& e) {
    EXPECT_NE(std::string(e.what()).find("is a STATUS bit"), std::string::npos) << e.what();
  }
}
