// SPDX-License-Identifier: GPL-2.0-or-later
// Manual "FRAMING" and "CRC": pre-parse framing with a command timeout in setup mode,
// timing-only framing in operate mode, bad CRCs never executed, a finite buffer.
#include "bench.hpp"

namespace i20::sim::test {
namespace {

namespace lc = lbp::local;

TEST(SimFraming, BadCrcIsNeverExecutedCountedAndUnanswered) {
  Bench b;
  lbp::Bytes wire = framed("65 00 30 34 12");
  wire.back() ^= 0x01;
  EXPECT_TRUE(b.raw(wire).empty()) << "no reply to a corrupt command";
  EXPECT_EQ(b.read(0x3000), 0u) << "not executed";
  EXPECT_EQ(b.local(0xC3), 1);
  EXPECT_EQ(b.local(0xC1), lc::kStatusCrcError);
  EXPECT_EQ(b.card.stats().bad_crc, 1u);
  // The next command is framed correctly: the bad one had the right length.
  EXPECT_EQ(b.send("DF"), reply("5A"));
}

TEST(SimFraming, CrcErrorCountSaturates) {
  Bench b;
  b.send("E3 FE");
  for (int i = 0; i < 3; ++i) b.raw(lbp::Bytes{0xDF, 0x00});
  EXPECT_EQ(b.local(0xC3), 0xFF);
}

TEST(SimFraming, GapsInsideACommandAreFineInSetupMode) {
  Bench b;
  const auto wire = framed("45 74 08");
  for (lbp::Byte byte : wire) {
    EXPECT_TRUE(b.card.take_output().empty());
    b.card.receive(lbp::ByteView(&byte, 1), b.t);
    b.t += 1500us;  // well inside 25.5 character times (~2.2 ms)
    b.card.advance(b.t);
  }
  EXPECT_EQ(b.card.take_output(), reply("20 E1"));
  EXPECT_EQ(b.local(0xC1), 0x00);
}

TEST(SimFraming, PartialCommandIsDroppedAfterTheTimeout) {
  Bench b;
  EXPECT_TRUE(b.raw(lbp::from_hex("45 74")).empty());
  EXPECT_TRUE(b.wait(3ms).empty());
  EXPECT_EQ(b.send("DF"), reply("5A")) << "the stale half command is gone, not glued to this one";
  EXPECT_EQ(b.local(0xC1), lc::kStatusCommandTimeout);
}

TEST(SimFraming, CommandTimeoutIsConfigurable) {
  Bench b;
  b.send("EB 0A");  // 1 character time (~87 us)
  b.raw(lbp::from_hex("45 74"));
  b.wait(500us);
  EXPECT_EQ(b.send("DF"), reply("5A"));
  EXPECT_TRUE(b.local(0xC1) & lc::kStatusCommandTimeout);
}

TEST(SimFraming, GarbageIsDiscardedUntilTheLineIsQuiet) {
  Bench b;
  // 0x01 cannot start a command; the cookie read right behind it is part of the noise.
  EXPECT_TRUE(b.raw(cat({lbp::Bytes{0x01}, framed("DF")})).empty());
  EXPECT_TRUE(b.card.framer_resyncing());
  b.wait(1ms);
  EXPECT_TRUE(b.send("DF").empty()) << "line not quiet long enough yet";
  b.wait(3ms);
  EXPECT_EQ(b.send("DF"), reply("5A"));
  EXPECT_TRUE(b.local(0xC1) & lc::kStatusCommandTimeout);
}

TEST(SimFraming, ContinuousNoiseKeepsTheCardDeaf) {
  Bench b;
  for (int i = 0; i < 10; ++i) {
    b.raw(lbp::Bytes{0x3F});
    b.wait(1ms);
  }
  EXPECT_TRUE(b.send("DF").empty());
  b.wait(2500us);
  EXPECT_EQ(b.send("DF"), reply("5A"));
}

TEST(SimFraming, ReceiveBufferOverflowsOnlyWhenTheCardCannotKeepUp) {
  Bench b;  // 128 bytes
  lbp::Bytes many;
  for (int i = 0; i < 200; ++i) many = cat({many, framed("DF")});
  EXPECT_EQ(b.raw(many).size(), 400u) << "an idle card executes as bytes arrive";
  EXPECT_EQ(b.local(0xC1), 0x00);
}

TEST(SimFraming, OverflowDropsBytesAndSetsBit4) {
  DeviceOptions o;
  o.rx_buffer_bytes = 8;
  Bench b(o);
  b.send("EC 01");
  lbp::Bytes burst = framed("65 02 00 E8 03");  // EEPROM busy for 2 ms
  for (int i = 0; i < 6; ++i) burst = cat({burst, framed("DF")});
  b.raw(burst);
  EXPECT_EQ(b.card.rx_pending(), 8u);
  const auto out = b.wait(2ms);
  EXPECT_EQ(out.size(), 1u + 4 * 2);
  EXPECT_EQ(b.local(0xC1), lc::kStatusBufferOverflow);
}

class SimOperate : public ::testing::Test {
 protected:
  static DeviceOptions options() {
    DeviceOptions o;
    o.mode = FramingMode::Operate;
    return o;
  }
  Bench b{options()};
  // 25.5 character times at 2.5 MBaud = 102 us.
  static constexpr auto kGap = 200us;
};

TEST_F(SimOperate, APacketIsExecutedOnlyAfterTheGap) {
  EXPECT_EQ(b.card.baud(), 2500000u);
  EXPECT_TRUE(b.send("DF").empty()) << "timing framing: the packet is not over yet";
  EXPECT_EQ(b.wait(kGap), reply("5A"));
}

TEST_F(SimOperate, SeveralCommandsInOnePacket) {
  b.raw(cat({framed("DF"), framed("81")}));
  EXPECT_EQ(b.wait(kGap), cat({reply("5A"), reply("00 7D AC 0D")}));
}

TEST_F(SimOperate, PartialPacketIsDroppedWhole) {
  b.raw(cat({framed("DF"), lbp::from_hex("45 74")}));
  EXPECT_TRUE(b.wait(kGap).empty()) << "the whole packet is untrusted";
  b.send("C1");
  EXPECT_EQ(b.wait(kGap), reply("40"));
}

TEST_F(SimOperate, GarbagePacketIsDroppedAndTheNextOneWorks) {
  b.raw(cat({lbp::Bytes{0x02}, framed("DF")}));
  EXPECT_TRUE(b.wait(kGap).empty());
  b.send("DF");
  EXPECT_EQ(b.wait(kGap), reply("5A"));
}

TEST_F(SimOperate, AGapSplitsPackets) {
  b.raw(lbp::from_hex("45 74"));  // half a command, then a gap: dropped
  b.t += kGap;
  b.raw(cat({lbp::from_hex("08"), lbp::Bytes{lbp::crc8(lbp::from_hex("45 74 08"))}}));
  EXPECT_TRUE(b.wait(kGap).empty()) << "the tail alone is not a command either";
  EXPECT_GE(b.card.framer_dropped_bytes(), 4u);
}

// Fuzz finding (fuzz/regressions/sim_8i20/rpcmem-rewrites-rpc-in-same-packet): one
// packet enables RPCMEM, rewrites RPC 6 (slot 0x30) into "write 2 stream bytes at 0",
// then invokes RPC 6 with no stream bytes. The packet was cut against the old (empty)
// list; running the new one read past the end of the command. The card parses each
// command when its turn comes (manual "FRAMING": a command's length follows from its
// header and, for an RPC, the stored list), so RPC 6 no longer fits the bytes it was cut
// with: it and the rest of the packet are dropped, as a packet that is not a whole number
// of commands is.
TEST_F(SimOperate, AnRpcRewrittenEarlierInItsPacketIsNotRunWithTheOldLength) {
  const lbp::Bytes packet = lbp::from_hex("EA 01 CC 65 30 00 65 00 2E 86 51");
  ASSERT_EQ(packet, cat({framed("EA 01"), framed("65 30 00 65 00"), framed("86")})) << "the CRCs are right";
  b.raw(packet);
  EXPECT_EQ(b.wait(kGap), cat({reply(""), reply("")}))
      << "RPCMEM on and the table write are answered, RPC 6 is not";
  EXPECT_EQ(b.card.rpc_table()[0x30], 0x65) << "the table write itself took effect";
  EXPECT_EQ(b.card.rpc_table()[0x00], 0x65) << "RPC 6's new list (write at 0) did not run";
  EXPECT_GE(b.card.framer_dropped_bytes(), 2u);
  b.send("C1");
  EXPECT_TRUE(b.wait(kGap).front() & lbp::local::kStatusCommandTimeout) << "flagged like a framing error";
}

TEST_F(SimOperate, AnRpcRewrittenInAnEarlierPacketRunsItsNewList) {
  // RPC 6 := read 2 bytes at STATUS (45 addr), terminator.
  const std::uint16_t status = b.address_of("STATUS");
  const std::string status_hex =
      lbp::to_hex(lbp::Bytes{static_cast<lbp::Byte>(status), static_cast<lbp::Byte>(status >> 8)});
  b.raw(cat({framed("EA 01"), framed("66 30 00 45 " + status_hex + " 00"), framed("EA 00")}));
  EXPECT_EQ(b.wait(kGap), cat({reply(""), reply(""), reply("")}));
  b.send("86");
  const lbp::Bytes answer = b.wait(kGap);
  ASSERT_EQ(answer.size(), 3u);
  EXPECT_EQ(lbp::read_le(lbp::ByteView(answer).first(2)), b.card.amplifier().status());
}

// Found by fuzz/sim_8i20 (fuzz/regressions/sim_8i20/operate-reset-with-no-deaf-time): a
// reset when the gap closes a packet, with a reset time of zero, left its end behind as an
// event due at the time just processed, so i20sim's loop would spin on it.
TEST(SimOperateReset, AResetThatIsAlreadyOverIsNotAnEventToCome) {
  DeviceOptions o;
  o.mode = FramingMode::Operate;
  o.reset_time = Clock::duration::zero();
  o.injection.reset_after_commands = 1;
  Bench b(o);
  b.send("DF");
  EXPECT_EQ(b.wait(200us), reply("5A")) << "answered, then reset";
  EXPECT_EQ(b.card.stats().resets, 1u);
  const auto next = b.card.next_event();
  EXPECT_TRUE(!next || *next > b.t) << "an event at or before now: the caller would spin";
  b.send("DF");
  EXPECT_EQ(b.wait(200us), reply("5A")) << "no deaf time: the next packet is answered";
}

}  // namespace
}  // namespace i20::sim::test
