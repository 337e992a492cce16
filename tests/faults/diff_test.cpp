// SPDX-License-Identifier: GPL-2.0-or-later
// What `watch` reports between two readings.
#include <gtest/gtest.h>

#include "faults/bit_diff.hpp"

using namespace i20::faults;

namespace {

std::vector<std::string> labels(const std::vector<DecodedBit>& bits) {
  std::vector<std::string> out;
  for (const auto& b : bits) out.push_back(b.label());
  return out;
}

}  // namespace

TEST(FaultWatch, FaultsThatAppearRise) {
  const auto d = diff(Register::Fault, 0x0000, 0x0102);
  EXPECT_FALSE(d.empty());
  EXPECT_EQ(labels(d.rose), (std::vector<std::string>{"NOENABLEFAULT", "BUSLOVFAULT"}));
  EXPECT_TRUE(d.fell.empty());
  EXPECT_EQ(d.rose_bits(), 0x0102);
  EXPECT_EQ(d.fell_bits(), 0);
}

TEST(FaultWatch, AClearedFaultFallsWhileAPersistingOneStays) {
  // After CLEARFAULT with the supply still off: no-enable cleared, bus under-voltage back.
  const auto d = diff(Register::Fault, 0x0102, 0x0100);
  EXPECT_TRUE(d.rose.empty());
  EXPECT_EQ(labels(d.fell), (std::vector<std::string>{"NOENABLEFAULT"}));
  EXPECT_EQ(d.before, 0x0102);
  EXPECT_EQ(d.after, 0x0100);
}

TEST(FaultWatch, RiseAndFallInOneStep) {
  const auto d = diff(Register::Fault, 0x0001, 0x0010);
  EXPECT_EQ(labels(d.rose), (std::vector<std::string>{"CURRENTFAULT"}));
  EXPECT_EQ(labels(d.fell), (std::vector<std::string>{"WATCHDOGFAULT"}));
}

TEST(FaultWatch, NoChangeIsEmpty) {
  const auto d = diff(Register::Fault, 0x0102, 0x0102);
  EXPECT_TRUE(d.empty());
  EXPECT_TRUE(d.rose.empty());
  EXPECT_TRUE(d.fell.empty());
}

TEST(FaultWatch, ReservedBitsAreReportedToo) {
  const auto d = diff(Register::Fault, 0x0000, 0x1000);
  ASSERT_EQ(d.rose.size(), 1u);
  EXPECT_TRUE(d.rose[0].reserved());
  EXPECT_EQ(d.rose[0].meaning(), "reserved/undocumented bit 12 set");
}

TEST(StatusWatch, LiveBitsComeAndGo) {
  const auto d = diff(Register::Status, 0x0202, 0x0204);
  EXPECT_EQ(labels(d.rose), (std::vector<std::string>{"BRAKEWASONSTATUS"}));
  EXPECT_EQ(labels(d.fell), (std::vector<std::string>{"BRAKESTATUS"}));
  EXPECT_EQ(d.reg, Register::Status);
}
