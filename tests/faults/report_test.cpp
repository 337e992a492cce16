// SPDX-License-Identifier: GPL-2.0-or-later
// The structured report the CLI renders as text or JSON.
#include "faults/report.hpp"

#include <gtest/gtest.h>

using namespace i20::faults;

TEST(FaultReport, TitleNamesEverySetFault) {
  const auto r = fault_report(0x0102);
  EXPECT_EQ(r.title, "FAULT 0x0102: 2 faults set: NOENABLEFAULT (bit 1), BUSLOVFAULT (bit 8)");
  ASSERT_EQ(r.lines.size(), 2u);
  EXPECT_EQ(r.lines[0].slug, "no-enable");
  EXPECT_EQ(r.lines[1].slug, "bus-under-voltage");
  EXPECT_FALSE(r.lines[0].checks.empty());
  EXPECT_FALSE(r.lines[0].causes.empty());
  EXPECT_EQ(r.lines[0].severity, Impact::Fault);
  EXPECT_FALSE(r.notes.empty());
  EXPECT_EQ(r.fault_output_on, false);  // no-enable cannot be masked
}

TEST(FaultReport, NoFaults) {
  const auto r = fault_report(0);
  EXPECT_EQ(r.title, "FAULT 0x0000: no faults");
  EXPECT_TRUE(r.lines.empty());
  EXPECT_TRUE(r.notes.empty());
  EXPECT_EQ(r.fault_output_on, true);
}

TEST(FaultReport, WithFaultmaskTheMaskedFaultIsMarked) {
  const auto r = fault_report(0x0100, 0xFEFF);
  EXPECT_EQ(r.title, "FAULT 0x0100 (FAULTMASK 0xFEFF): 1 fault set: BUSLOVFAULT (bit 8, masked)");
  ASSERT_EQ(r.lines.size(), 1u);
  EXPECT_TRUE(r.lines[0].masked);
  EXPECT_TRUE(r.lines[0].maskable);
  EXPECT_EQ(r.fault_output_on, true);
  EXPECT_EQ(r.faultmask, 0xFEFF);
}

TEST(FaultReport, WithoutFaultmaskTheOutputStateOfAMaskableFaultIsUnknown) {
  const auto r = fault_report(0x0100);
  EXPECT_FALSE(r.fault_output_on.has_value());
  EXPECT_FALSE(r.lines[0].masked);
  EXPECT_EQ(fault_report(0x0100, 0xFFFF).fault_output_on, false);
}

TEST(FaultReport, ReservedBitsGetALineOfTheirOwn) {
  const auto r = fault_report(0x1002);
  EXPECT_EQ(r.title, "FAULT 0x1002: 2 faults set: NOENABLEFAULT (bit 1), reserved (bit 12)");
  ASSERT_EQ(r.lines.size(), 2u);
  EXPECT_TRUE(r.lines[1].reserved);
  EXPECT_EQ(r.lines[1].bit, 12u);
  EXPECT_EQ(r.lines[1].meaning, "reserved/undocumented bit 12 set");
  EXPECT_TRUE(r.lines[1].name.empty());
  EXPECT_FALSE(r.lines[1].checks.empty());
}

TEST(FaultReport, LinesCarryTheKnowledgeBaseEntry) {
  const auto r = fault_report(0x0001);
  ASSERT_EQ(r.lines.size(), 1u);
  const auto& line = r.lines[0];
  const BitInfo& b = *FaultTable::builtin().find(Register::Fault, 0);
  EXPECT_EQ(line.name, b.name);
  EXPECT_EQ(line.meaning, b.meaning);
  EXPECT_EQ(line.causes, b.causes);
  EXPECT_EQ(line.checks, b.checks);
  EXPECT_EQ(line.source, b.source);
  EXPECT_EQ(line.linuxcnc_pin, "fault.watchdog");
  EXPECT_TRUE(line.sticky);
  EXPECT_TRUE(line.clears_while_cause_persists);
}

TEST(StatusReport, TitleAndLines) {
  const auto r = status_report(0x0204);
  EXPECT_EQ(r.title, "STATUS 0x0204: 2 bits set: BRAKEWASONSTATUS (bit 2), PIDONSTATUS (bit 9)");
  EXPECT_FALSE(r.fault_output_on.has_value());
  EXPECT_EQ(r.lines[1].severity, Impact::Info);
  EXPECT_EQ(status_report(0).title, "STATUS 0x0000: no bits set");
  EXPECT_EQ(status_report(0x0100).title, "STATUS 0x0100: 1 bit set: NOENABLESTATUS (bit 8)");
}
