// SPDX-License-Identifier: GPL-2.0-or-later
// Manual "LOCAL LBP COMMANDS" and docs/facts.md s2 (NV access 0xEC/0xCC): every local read
// and write, sent as raw bytes.
#include "bench.hpp"
#include "sim/bits.hpp"

namespace i20::sim::test {
namespace {

TEST(SimLocal, EveryReadAnswersOneByteAndItsCrc) {
  Bench b;
  EXPECT_EQ(b.send("C0"), reply("00"));  // unit address
  EXPECT_EQ(b.send("C1"), reply("00"));  // LBP status: clean after power-up
  EXPECT_EQ(b.send("C2"), reply("01"));  // CRC always enabled
  EXPECT_EQ(b.send("C3"), reply("00"));  // CRC error count
  EXPECT_EQ(b.send("CA"), reply("00"));  // RPCMEM flag off
  EXPECT_EQ(b.send("CB"), reply("FF"));  // 25.5 character times
  EXPECT_EQ(b.send("CC"), reply("00"));  // NV access: RAM
  EXPECT_EQ(b.send("D0"), reply("38"));  // '8'
  EXPECT_EQ(b.send("D1"), reply("49"));  // 'I'
  EXPECT_EQ(b.send("D2"), reply("32"));  // '2'
  EXPECT_EQ(b.send("D3"), reply("30"));  // '0'
  EXPECT_EQ(b.send("D8"), reply("00"));
  EXPECT_EQ(b.send("D9"), reply("00"));
  EXPECT_EQ(b.send("DA"), reply("03"));  // LBP version (simulator's choice)
  EXPECT_EQ(b.send("DB"), reply("00"));
  EXPECT_EQ(b.send("DC"), reply("08"));  // RPC pitch
  EXPECT_EQ(b.send("DD"), reply("00"));  // RPC size 0x0200
  EXPECT_EQ(b.send("DE"), reply("02"));
  EXPECT_EQ(b.send("DF"), reply("5A"));  // cookie
  EXPECT_EQ(b.send("C5"), reply("00"));  // reserved reads still answer
}

TEST(SimLocal, WritesAnswerASingleZeroAndTakeEffect) {
  Bench b;
  EXPECT_EQ(b.send("E1 20"), lbp::Bytes{0x00});
  EXPECT_EQ(b.local(0xC1), 0x20);
  b.send("E1 00");
  EXPECT_EQ(b.local(0xC1), 0x00);
  b.send("E3 07");
  EXPECT_EQ(b.local(0xC3), 0x07);
  b.send("EA 01");
  EXPECT_EQ(b.local(0xCA), 0x01);
  b.send("EA 00");
  EXPECT_EQ(b.local(0xCA), 0x00);
  b.send("EB 40");
  EXPECT_EQ(b.local(0xCB), 0x40);
  b.send("FD 07");
  EXPECT_EQ(b.local(0xDB), 0x07);
  EXPECT_EQ(b.send("F7 A5"), lbp::Bytes{0x00});
  EXPECT_EQ(b.card.lbp_registers().leds, 0xA5);
  EXPECT_EQ(b.send("E2 00"), lbp::Bytes{0x00});
  EXPECT_EQ(b.local(0xC2), 0x01) << "CRC checking cannot be switched off";
  EXPECT_EQ(b.send("FF"), lbp::Bytes{0x00});
  EXPECT_EQ(b.send("E5 12"), lbp::Bytes{0x00});  // reserved write: accepted, no effect
}

TEST(SimLocal, AddressPointerCommands) {
  Bench b;
  b.send("F8 34");
  b.send("F9 12");
  EXPECT_EQ(b.local(0xD8), 0x34);
  EXPECT_EQ(b.local(0xD9), 0x12);
  b.send("FA F0");  // 0x1234 + 0xF0 carries into the high byte
  EXPECT_EQ(b.local(0xD8), 0x24);
  EXPECT_EQ(b.local(0xD9), 0x13);
  // The pointer is the one data commands without an address use.
  b.card.amplifier().write_ram(0x1324, lbp::Bytes{0x11, 0x22});
  EXPECT_EQ(b.send("41"), reply("11 22"));
}

TEST(SimLocal, NvAccessModeIsSetAndRead) {
  Bench b;
  b.send("EC 01");
  EXPECT_EQ(b.local(0xCC), 0x01);
  b.send("EC 02");
  EXPECT_EQ(b.local(0xCC), 0x02);
  b.send("EC 00");
  EXPECT_EQ(b.local(0xCC), 0x00);
  EXPECT_EQ(b.send("EC 03"), lbp::Bytes{0x00});
  EXPECT_EQ(b.local(0xCC), 0x00) << "mode 3 does not exist";
  EXPECT_EQ(b.local(0xC1) & lbp::local::kStatusInvalidWrite, lbp::local::kStatusInvalidWrite);
}

TEST(SimLocal, ResetNeedsTheKeyByte) {
  Bench b;
  b.send("F8 44");
  EXPECT_EQ(b.send("FE 00"), lbp::Bytes{0x00});
  EXPECT_EQ(b.local(0xD8), 0x44) << "0xFE without 0x5A must not reset";
  EXPECT_EQ(b.read("STATUS") & status::kSoftwareReset, 0u);
  EXPECT_EQ(b.card.stats().resets, 0u);

  EXPECT_EQ(b.send("FE 5A"), lbp::Bytes{0x00}) << "the reset is answered before it happens";
  EXPECT_EQ(b.card.stats().resets, 1u);
  b.wait(5ms);
  EXPECT_EQ(b.local(0xD8), 0x00) << "the LBP state starts over";
  const auto st = b.read("STATUS");
  EXPECT_TRUE(st & status::kSoftwareReset);
  EXPECT_TRUE(st & status::kExternalReset) << "sticky bits survive a reset";
}

TEST(SimLocal, ResetDropsWhatFollowsAndIsDeafBriefly) {
  Bench b;
  // Reset and a cookie read back to back: the cookie is lost with the processor's state.
  const auto out = b.raw(cat({framed("FE 5A"), framed("DF")}));
  EXPECT_EQ(out, lbp::Bytes{0x00});
  EXPECT_TRUE(b.send("DF").empty()) << "still rebooting";
  b.wait(2ms);
  EXPECT_EQ(b.send("DF"), reply("5A"));
}

TEST(SimLocal, ResetRestoresLbpDefaults) {
  Bench b;
  b.send("EA 01");
  b.send("EC 01");
  b.send("EB 20");
  b.send("FE 5A");
  b.wait(2ms);
  EXPECT_EQ(b.local(0xCA), 0x00);
  EXPECT_EQ(b.local(0xCC), 0x00);
  EXPECT_EQ(b.local(0xCB), 0xFF);
}

}  // namespace
}  // namespace i20::sim::test
