// SPDX-License-Identifier: GPL-2.0-or-later
// Manual "LBP DATA READ/WRITE COMMAND" and "EXAMPLE LBP COMMANDS": address pointer,
// auto-increment, 1/2/4/8-byte accesses, little-endian data, read-only parameters.
#include "bench.hpp"

namespace i20::sim::test {
namespace {

TEST(SimData, ManualExampleWriteFourWriteTwoReadEight) {
  Bench b;
  // 0x6E: write, AI, 2-byte address, 4 data: AA BB CC DD at 0x10..0x13, pointer left at 0x14.
  EXPECT_EQ(b.send("6E 10 00 AA BB CC DD"), lbp::Bytes{0x00});
  EXPECT_EQ(b.local(0xD8), 0x14);
  // 0x61: write 2 at the current address, no AI.
  EXPECT_EQ(b.send("61 EE FF"), lbp::Bytes{0x00});
  EXPECT_EQ(b.local(0xD8), 0x14) << "no AutoInc: the pointer stays";
  // 0x47: read 8 at 0x10.
  EXPECT_EQ(b.send("47 10 00"), reply("AA BB CC DD EE FF 00 00"));
}

TEST(SimData, EverySizeReadsSuccessiveAddressesLittleEndian) {
  Bench b;
  b.send("6F 00 30 01 02 03 04 05 06 07 08");
  EXPECT_EQ(b.send("44 00 30"), reply("01"));
  EXPECT_EQ(b.send("45 00 30"), reply("01 02"));
  EXPECT_EQ(b.send("46 00 30"), reply("01 02 03 04"));
  EXPECT_EQ(b.send("47 00 30"), reply("01 02 03 04 05 06 07 08"));
  EXPECT_EQ(b.read(0x3001, 4), 0x05040302u);
}

TEST(SimData, AutoIncrementWalksThePointer) {
  Bench b;
  b.send("6F 00 30 01 02 03 04 05 06 07 08");
  b.send("F8 00");
  b.send("F9 30");
  EXPECT_EQ(b.send("48"), reply("01"));     // read 1 at pointer, AI
  EXPECT_EQ(b.send("49"), reply("02 03"));  // read 2 at pointer, AI
  EXPECT_EQ(b.send("4A"), reply("04 05 06 07"));
  EXPECT_EQ(b.send("40"), reply("08")) << "no AI: pointer stays at 0x3007";
  EXPECT_EQ(b.send("40"), reply("08"));
  EXPECT_EQ(b.local(0xD8), 0x07);
  // An explicit address loads the pointer even without AI.
  b.send("45 10 30");
  EXPECT_EQ(b.local(0xD8), 0x10);
}

TEST(SimData, WritesWithRidOutsideAnRpcTakeDataFromTheStream) {
  Bench b;
  // 0x75 = write, RID, 2-byte address, 2 data: RID is ignored outside RPCs.
  EXPECT_EQ(b.send("75 00 31 34 12"), lbp::Bytes{0x00});
  EXPECT_EQ(b.read(0x3100), 0x1234u);
}

TEST(SimData, IdentityRegisters) {
  Bench b;
  EXPECT_EQ(b.send("45 74 08"), reply("20 E1")) << "SWREVISION at 2164";
  EXPECT_EQ(b.send("46 28 09"), reply("45 23 01 00")) << "UNITNUMBER at 2344";
  DeviceOptions o;
  o.amplifier.unit_number = 0xCAFE0042;
  Bench other(o);
  EXPECT_EQ(other.read(2344, 4), 0xCAFE0042u);
}

TEST(SimData, WorkingParametersAreWritable) {
  Bench b;
  EXPECT_EQ(b.write16(b.address_of("MAXCURRENT"), 2500), lbp::Bytes{0x00});
  EXPECT_EQ(b.read("MAXCURRENT"), 2500u);
  EXPECT_EQ(b.local(0xC1), 0x00);
}

class SimReadOnly : public ::testing::TestWithParam<const char*> {};

TEST_P(SimReadOnly, WriteIsRefusedAnsweredAndFlagged) {
  Bench b;
  const auto& r = b.card.amplifier().map().at(GetParam());
  const auto before = b.read(r.address, r.bytes());
  const lbp::Bytes out = r.bytes() == 4 ? b.send("66 28 09 11 22 33 44") : b.write16(r.address, 0x5555);
  EXPECT_EQ(out, lbp::Bytes{0x00}) << "the command is still answered";
  EXPECT_EQ(b.read(r.address, r.bytes()), before);
  EXPECT_EQ(b.local(0xC1), lbp::local::kStatusInvalidWrite);
}

INSTANTIATE_TEST_SUITE_P(Registers, SimReadOnly,
                         ::testing::Values("FAULT", "STATUS", "BUSV", "TEMPERATURE", "SWREVISION",
                                           "UNITNUMBER"));

TEST(SimData, AWriteTouchingAReadOnlyByteIsRefusedWhole) {
  Bench b;
  // 4 bytes at FAULTMASK (0x0806) run into BUSV (0x0808): nothing is written.
  EXPECT_EQ(b.send("66 06 08 00 00 00 00"), lbp::Bytes{0x00});
  EXPECT_EQ(b.read("FAULTMASK"), 0xFFFFu);
  EXPECT_TRUE(b.local(0xC1) & lbp::local::kStatusInvalidWrite);
  b.send("E1 00");
  EXPECT_EQ(b.local(0xC1), 0x00) << "0xE1 0 clears the error bits";
}

TEST(SimData, AddressesWrapAtTheTop) {
  Bench b;
  b.send("66 FE FF 01 02 03 04");
  EXPECT_EQ(b.read(0xFFFE, 2), 0x0201u);
  EXPECT_EQ(b.read(0x0000, 2), 0x0403u);
}

}  // namespace
}  // namespace i20::sim::test
