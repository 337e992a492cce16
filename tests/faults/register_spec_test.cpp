// SPDX-License-Identifier: GPL-2.0-or-later
// Register values given as the bits that are set, the way LinuxCNC shows them: hostmot2 pin
// names (LinuxCNC sserial.h hm2_8i20_params, sserial(9); docs/facts.md s4), with or
// without the device prefix halshow shows, slugs and the manual's names (FAULT CONDITIONS).
#include "faults/register_spec.hpp"

#include <gtest/gtest.h>

using namespace i20::faults;

TEST(RegisterSpec, NumbersAreReadAsBefore) {
  EXPECT_EQ(parse_register_spec("0x0102", Register::Fault), 0x0102);
  EXPECT_EQ(parse_register_spec("258", Register::Fault), 0x0102);
  EXPECT_THROW(parse_register_spec("0102", Register::Fault), BadRegisterValue);  // lost hex prefix
}

TEST(RegisterSpec, PinNamesGiveTheirManualBits) {
  // sserial.h: FAULT bits 1 no-enable, 8 bus-underv, 9 bus-high (settable), 10 bus-overv (400 V).
  EXPECT_EQ(parse_register_spec("fault.no-enable,fault.bus-underv", Register::Fault), 0x0102);
  EXPECT_EQ(parse_register_spec("fault.bus-high", Register::Fault), 1u << 9);
  EXPECT_EQ(parse_register_spec("fault.bus-overv", Register::Fault), 1u << 10);
  EXPECT_EQ(parse_register_spec("fault.framingr", Register::Fault), 1u << 15);
  // STATUS bits only hostmot2 names: 3 bus-underv, 8 no-enable, 9 pid-on.
  EXPECT_EQ(parse_register_spec("status.pid-on+status.no-enable", Register::Status), 0x0300);
  EXPECT_EQ(parse_register_spec("hm2_7i96s.0.8i20.0.0.status.bus-underv", Register::Status), 1u << 3);
  EXPECT_EQ(parse_register_spec("hm2_8i20.001f.fault.watchdog", Register::Fault), 1u);
  // Slugs and the manual's names mix with pins.
  EXPECT_EQ(parse_register_spec("no-enable+BUSLOVFAULT", Register::Fault), 0x0102);
}

TEST(RegisterSpec, WrongOrUnknownNamesAreRefusedByName) {
  try {
    parse_register_spec("status.pid-on", Register::Fault);
    FAIL();
  } catch (const UnknownBit& e) {
    EXPECT_NE(std::string(e.what()).find("is a STATUS bit, not a FAULT bit"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_register_spec("fault.nope", Register::Fault), UnknownBit);
  EXPECT_THROW(parse_register_spec("fault.no-enable,", Register::Fault), BadRegisterValue);
}

TEST(RegisterSpec, MaskTakesPinsToo) {
  const auto& table = FaultTable::builtin();
  EXPECT_EQ(table.get(Register::Fault, "fault.bus-underv").bit, 8u);
  EXPECT_EQ(table.get(Register::Fault, "hm2_7i96s.0.8i20.1.3.fault.bus-underv").bit, 8u);
}
