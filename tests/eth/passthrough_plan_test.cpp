// SPDX-License-Identifier: GPL-2.0-or-later
// LBP command -> SSLBP setup-mode passthrough registers (8I20 manual, "SETUP MODE
// OPERATION"; docs/facts.md section 5).
#include "eth/passthrough_plan.hpp"

#include <gtest/gtest.h>

#include "link/link.hpp"

using namespace i20;
using namespace i20::eth;
using lbp::DataSize;

TEST(EthPassthroughPlan, WordReadIs0x45InTheHighByteOfCs) {
  const auto step = plan_passthrough(lbp::read(2344 /*UNITNUMBER*/, DataSize::Two));
  EXPECT_EQ(step.cs, 0x45000928u);
  EXPECT_FALSE(step.interface0);
  EXPECT_EQ(step.reply_bytes, 2u);
  EXPECT_TRUE(step.repeatable);
  EXPECT_EQ(step.wire_bytes, 4u + 3u);  // 45 28 09 crc, then 2 data + crc
}

TEST(EthPassthroughPlan, WordWriteCarriesItsDataInInterface0) {
  const auto step = plan_passthrough(lbp::write(10 /*NVKQP*/, DataSize::Two, 0x1234));
  EXPECT_EQ(step.cs, 0x6500000Au);
  EXPECT_EQ(step.interface0, 0x1234u);
  EXPECT_EQ(step.reply_bytes, 0u);
  EXPECT_TRUE(step.data_write);
}

TEST(EthPassthroughPlan, ByteAndLongAccesses) {
  EXPECT_EQ(plan_passthrough(lbp::read(0x0010, DataSize::One)).cs, 0x44000010u);
  const auto write4 = plan_passthrough(lbp::write(0x0816, DataSize::Four, 150000));
  EXPECT_EQ(write4.cs, 0x66000816u);
  EXPECT_EQ(write4.interface0, 150000u);
  EXPECT_EQ(plan_passthrough(lbp::read(0x0816, DataSize::Four)).reply_bytes, 4u);
  // Auto-increment travels in the header unchanged; the address comes from CS.
  EXPECT_EQ(plan_passthrough(lbp::read(0x0020, DataSize::One, true)).cs, 0x4C000020u);
}

TEST(EthPassthroughPlan, LocalCommandsGoInTheHighByte) {
  const auto cookie = plan_passthrough(lbp::local_read(lbp::local::kGetCookie));
  EXPECT_EQ(cookie.cs, 0xDF000000u);
  EXPECT_EQ(cookie.reply_bytes, 1u);
  const auto nv = plan_passthrough(lbp::set_nv_access(lbp::local::NvAccess::Eeprom));
  EXPECT_EQ(nv.cs, 0xEC000000u);
  EXPECT_EQ(nv.interface0, 1u);
  EXPECT_EQ(nv.nv_access_mode, 1);
  EXPECT_EQ(plan_passthrough(lbp::set_nv_access(lbp::local::NvAccess::Ram)).interface0, 0u);
}

TEST(EthPassthroughPlan, ResetAndAddToAddressAreNotRepeatable) {
  EXPECT_FALSE(plan_passthrough(lbp::reset_processor()).repeatable);
  EXPECT_FALSE(plan_passthrough(lbp::local_write(lbp::local::kAddToAddress, 2)).repeatable);
  EXPECT_TRUE(plan_passthrough(lbp::local_write(lbp::local::kSetLowAddress, 2)).repeatable);
}

TEST(EthPassthroughPlan, RefusesWhatTheRegistersCannotCarry) {
  const lbp::Command cannot[] = {
      lbp::read(0x0010, DataSize::Eight),                           // 8 bytes: INTERFACE0 is 32 bits
      lbp::write(0x0010, DataSize::Eight, 1),                       //
      lbp::read_at_pointer(DataSize::Two),                          // no address
      lbp::write_at_pointer(DataSize::Two, 1),                      //
      lbp::rpc(3, lbp::Bytes{0, 0, 0, 0}, 8),                       // RPC
      lbp::reset_parser(),                                          // 0xFF has no data byte
      lbp::Command{.bytes = {0x12}, .reply_bytes = 0},              // not an LBP command
      lbp::Command{.bytes = {0x55, 0x10, 0x00}, .reply_bytes = 2},  // RID: data from an RPC
  };
  for (const auto& c : cannot) {
    EXPECT_THROW(plan_passthrough(c), link::UnsupportedCommand) << lbp::to_hex(c.bytes);
  }
  try {
    plan_passthrough(lbp::read(0x0010, DataSize::Eight));
  } catch (const link::UnsupportedCommand& e) {
    EXPECT_NE(std::string(e.what()).find("8-byte"), std::string::npos) << e.what();
  }
}

TEST(EthPassthroughPlan, ReplyIsTheLowBytesOfInterface0) {
  EXPECT_EQ(reply_from_interface0(0xAABBCCDD, 2), (lbp::Bytes{0xDD, 0xCC}));
  EXPECT_EQ(reply_from_interface0(0xAABBCCDD, 0), lbp::Bytes{});
}
