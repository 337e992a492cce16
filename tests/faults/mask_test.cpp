// SPDX-License-Identifier: GPL-2.0-or-later
// FAULTMASK rules (manual, FAULT MASK): a 0 bit masks, only BUSLOVFAULT is maskable.
#include <gtest/gtest.h>

#include "faults/fault_mask.hpp"

using namespace i20::faults;

namespace {

std::string not_maskable(std::string_view key) {
  try {
    maskable_fault(key);
  } catch (const NotMaskable& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace

TEST(FaultMask, MaskingBusUnderVoltageClearsBit8) {
  EXPECT_EQ(set_fault_masked(0xFFFF, "bus-under-voltage", true), 0xFEFF);
  EXPECT_EQ(set_fault_masked(0xFEFF, "bus-under-voltage", false), 0xFFFF);
  EXPECT_EQ(set_fault_masked(0xFEFF, "bus-under-voltage", true), 0xFEFF);  // idempotent
}

TEST(FaultMask, OtherBitsStayAsRead) {
  EXPECT_EQ(set_fault_masked(0x7FFF, "bus-under-voltage", true), 0x7EFF);
  EXPECT_EQ(set_fault_masked(0x0000, "bus-under-voltage", false), 0x0100);
}

TEST(FaultMask, AcceptsNamePinAndBitNumber) {
  for (const char* key : {"BUSLOVFAULT", "fault.bus-underv", "8", "Bus-Under-Voltage"})
    EXPECT_EQ(maskable_fault(key).bit, 8u) << key;
}

TEST(FaultMask, RefusesNonMaskableFaultsNamingTheMaskableOne) {
  const auto msg = not_maskable("no-enable");
  EXPECT_TRUE(contains(msg, "no-enable (FAULT bit 1, NOENABLEFAULT) cannot be masked")) << msg;
  EXPECT_TRUE(contains(msg, "only bus-under-voltage (FAULT bit 8, BUSLOVFAULT) is maskable")) << msg;
  for (const char* key : {"watchdog", "1", "OVERTEMPFAULT", "serial-framing"})
    EXPECT_FALSE(not_maskable(key).empty()) << key;
  EXPECT_THROW(set_fault_masked(0xFFFF, "watchdog", true), NotMaskable);
  EXPECT_THROW(set_fault_masked(0xFFFF, "watchdog", false), NotMaskable);
}

TEST(FaultMask, RefusesStatusBits) {
  const auto msg = not_maskable("status-bus-under-voltage");
  EXPECT_TRUE(contains(msg, "is a STATUS bit")) << msg;
  EXPECT_TRUE(contains(msg, "bus-under-voltage (FAULT bit 8")) << msg;
}

TEST(FaultMask, UnknownAndReservedBitsAreUnknown) {
  EXPECT_THROW(maskable_fault("bus-low"), UnknownBit);
  EXPECT_THROW(maskable_fault("3"), UnknownBit);
  EXPECT_THROW(maskable_fault("16"), UnknownBit);
}

TEST(FaultMask, ArithmeticRejectsBitsOutsideTheRegister) {
  EXPECT_EQ(mask_bit(0xFFFF, 8), 0xFEFF);
  EXPECT_EQ(unmask_bit(0xFEFF, 8), 0xFFFF);
  EXPECT_EQ(mask_bit(0xFFFF, 15), 0x7FFF);
  EXPECT_THROW(mask_bit(0xFFFF, 16), i20::UsageError);
  EXPECT_THROW(unmask_bit(0xFFFF, 99), i20::UsageError);
}

TEST(FaultMask, MaskedBusUnderVoltageKeepsTheFaultOutputOn) {
  const auto s = mask_state(0x0100, 0xFEFF);
  EXPECT_EQ(s.masked, 0x0100);
  EXPECT_EQ(s.unmasked, 0x0000);
  EXPECT_TRUE(s.fault_output_on());
  EXPECT_EQ(s.ineffective, 0);
}

TEST(FaultMask, UnmaskedFaultsStillOpenTheFaultOutput) {
  const auto s = mask_state(0x0102, 0xFEFF);
  EXPECT_EQ(s.masked, 0x0100);
  EXPECT_EQ(s.unmasked, 0x0002);
  EXPECT_FALSE(s.fault_output_on());
  EXPECT_FALSE(mask_state(0x0100, 0xFFFF).fault_output_on());
  EXPECT_TRUE(mask_state(0x0000, 0xFFFF).fault_output_on());
}

TEST(FaultMask, ZeroBitsOnNonMaskableFaultsHaveNoEffect) {
  // The manual gives FAULTMASK no effect outside BUSLOVFAULT: no-enable still trips.
  const auto s = mask_state(0x0002, 0xFFFD);
  EXPECT_EQ(s.masked, 0);
  EXPECT_EQ(s.unmasked, 0x0002);
  EXPECT_EQ(s.ineffective, 0x0002);
  EXPECT_FALSE(s.fault_output_on());
}
