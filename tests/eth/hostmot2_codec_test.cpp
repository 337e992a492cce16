// SPDX-License-Identifier: GPL-2.0-or-later
// HostMot2 identification, IDROM, module/pin descriptors and the SSERIAL register
// addresses (docs/facts.md section 5), and the SSLBP command words (8I20 manual, "SSLBP").
#include <gtest/gtest.h>

#include "lbp/error.hpp"
#include "hostmot2/hostmot2.hpp"

using namespace i20;
using namespace i20::lbp;
using namespace i20::lbp::hm2;

namespace {

Idrom usual_idrom() {
  Idrom r;
  r.board_name = "MESA7I96";
  r.io_ports = 3;
  r.io_width = 51;
  r.port_width = 17;
  r.clock_low = 100'000'000;
  r.instance_stride0 = 4;
  r.instance_stride1 = 0x40;
  r.register_stride0 = 0x100;
  r.register_stride1 = 4;
  return r;
}

ModuleDescriptor sserial_module(std::uint8_t instances = 1) {
  return ModuleDescriptor{.gtag = gtag::kSserial,
                          .version = 0,
                          .clock_tag = 1,
                          .instances = instances,
                          .base_address = 0x5B00,
                          .registers = 6,
                          .strides = 0x10,
                          .multiple_registers = 0x3C};
}

}  // namespace

TEST(HostMot2Codec, IdentAreaCookieConfigNameAndIdromPointer) {
  // What a card returns for 4 words at 0x100: cookie, "HOSTMOT2", 0x400.
  const Bytes bytes = from_hex("FECAAA55 484F53544D4F5432 00040000");
  const IdentArea a = IdentArea::parse(bytes);
  EXPECT_TRUE(a.valid());
  EXPECT_EQ(a.cookie, kCookie);
  EXPECT_EQ(a.config_name, "HOSTMOT2");
  EXPECT_EQ(a.idrom_address, 0x400u);
  EXPECT_EQ(a.encode(), bytes);
  EXPECT_FALSE(IdentArea::parse(Bytes(16, 0)).valid());
}

TEST(HostMot2Codec, IdromRoundTripsInFactsOrder) {
  const Idrom r = usual_idrom();
  const Bytes bytes = r.encode();
  ASSERT_EQ(bytes.size(), Idrom::kBytes);
  // Word 3..4 is the board name, word 7 IOPorts, word 14 RegisterStride0.
  EXPECT_EQ(std::string(bytes.begin() + 12, bytes.begin() + 20), "MESA7I96");
  EXPECT_EQ(read_le(ByteView(bytes).subspan(7 * 4, 4)), 3u);
  EXPECT_EQ(read_le(ByteView(bytes).subspan(14 * 4, 4)), 0x100u);
  const Idrom back = Idrom::parse(bytes);
  EXPECT_EQ(back.board_name, "MESA7I96");
  EXPECT_EQ(back.instance_stride1, 0x40u);
  EXPECT_EQ(back.register_stride0, 0x100u);
  EXPECT_THROW(Idrom::parse(Bytes(60)), ProtocolError);
}

TEST(HostMot2Codec, ModuleDescriptorLayout) {
  // GTag, Version, ClockTag, Instances, BaseAddress (16 bit), NumRegisters, Strides, MultipleRegs.
  const Bytes bytes = from_hex("C1 00 01 02 005B 06 10 3C000000");
  const ModuleDescriptor m = ModuleDescriptor::parse(bytes);
  EXPECT_EQ(m, sserial_module(2));
  EXPECT_EQ(m.encode(), bytes);
  const Idrom idrom = usual_idrom();
  EXPECT_EQ(m.register_stride(idrom), 0x100u);  // low nibble 0: RegisterStride0
  EXPECT_EQ(m.instance_stride(idrom), 0x40u);   // high nibble 1: InstanceStride1
  EXPECT_EQ(m.register_address(idrom, 2, 1), 0x5B00 + 0x200 + 0x40);
  EXPECT_THROW(m.register_address(idrom, 6, 0), UsageError);
  EXPECT_THROW(m.register_address(idrom, 0, 2), UsageError);
}

TEST(HostMot2Codec, ModuleListEndsAtGtagZero) {
  Bytes table = sserial_module().encode();
  const Bytes io =
      ModuleDescriptor{.gtag = gtag::kIoPort, .instances = 3, .base_address = 0x1000, .registers = 5}
          .encode();
  table.insert(table.end(), io.begin(), io.end());
  table.resize(table.size() + 12 * 3, 0);
  const Bytes after = sserial_module().encode();  // never reached
  table.insert(table.end(), after.begin(), after.end());
  const auto modules = parse_modules(table);
  ASSERT_EQ(modules.size(), 2u);
  EXPECT_EQ(modules[1].gtag, gtag::kIoPort);
}

TEST(HostMot2Codec, PinDescriptors) {
  const auto pins = parse_pins(from_hex("81050003 01C10003 00000003"), 3);
  ASSERT_EQ(pins.size(), 3u);
  EXPECT_EQ(pins[0].secondary_tag, gtag::kStepGen);
  EXPECT_EQ(pins[0].secondary_pin, 0x81);
  EXPECT_EQ(pins[1].secondary_tag, gtag::kSserial);
  EXPECT_EQ(pins[2].primary_tag, gtag::kIoPort);
  EXPECT_THROW(parse_pins(Bytes(8), 3), ProtocolError);
}

TEST(HostMot2Codec, SserialRegistersFromTheStrides) {
  const auto r = SserialRegisters::locate(usual_idrom(), sserial_module(2), 0);
  EXPECT_EQ(r.command, 0x5B00);
  EXPECT_EQ(r.data, 0x5C00);
  EXPECT_EQ(r.cs(0), 0x5D00);
  EXPECT_EQ(r.cs(3), 0x5D0C);
  EXPECT_EQ(r.interface0(0), 0x5E00);
  EXPECT_EQ(r.interface1(7), 0x5F1C);
  EXPECT_EQ(r.interface2(0), 0x6000);
  const auto second = SserialRegisters::locate(usual_idrom(), sserial_module(2), 1);
  EXPECT_EQ(second.command, 0x5B40);
  EXPECT_EQ(second.cs(1), 0x5D44);
  // Other strides move everything: computed, not constants.
  Idrom other = usual_idrom();
  other.register_stride0 = 0x80;
  other.instance_stride1 = 0x20;
  const auto moved = SserialRegisters::locate(other, sserial_module(2), 1);
  EXPECT_EQ(moved.data, 0x5B00 + 0x80 + 0x20);
  EXPECT_EQ(moved.interface0(2), 0x5B00 + 3 * 0x80 + 0x20 + 8);
  // SSERIALB (0xC6) uses the same interface; other modules are refused.
  ModuleDescriptor b = sserial_module();
  b.gtag = gtag::kSserialB;
  EXPECT_NO_THROW(SserialRegisters::locate(usual_idrom(), b, 0));
  b.gtag = gtag::kStepGen;
  EXPECT_THROW(SserialRegisters::locate(usual_idrom(), b, 0), UsageError);
}

TEST(HostMot2Codec, SslbpCommandWords) {
  using namespace sslbp;
  EXPECT_EQ(stop(), 0x0800u);
  EXPECT_EQ(stop(0x04), 0x0804u);
  EXPECT_EQ(start_normal(0x01), 0x0901u);
  EXPECT_EQ(start_setup(0x81), 0x0F81u);
  EXPECT_EQ(doit(0x03), 0x1003u);
  EXPECT_EQ(read_local(param::kChannels), 0x2007u);
  EXPECT_EQ(read_local(param::kClock), 0x2230u);
  EXPECT_EQ(write_local(0x10), 0xA010u);
  // Passthrough: 0x4500_0000 | addr reads a word, 0x6500_0000 | addr writes one, NV mode
  // through CS 0xEC00_0000.
  EXPECT_EQ(passthrough_cs(0x45, 0x0928), 0x45000928u);
  EXPECT_EQ(passthrough_cs(0x65, 0x000A), 0x6500000Au);
  EXPECT_EQ(passthrough_cs(0xEC), 0xEC000000u);
}

TEST(HostMot2Codec, ChannelStatusInWords) {
  using sslbp::ChannelStatus;
  EXPECT_EQ(ChannelStatus{0x800F0000}.describe(), "ok");
  EXPECT_EQ(ChannelStatus{0x800F0000}.remote_mode(), sslbp::kRemoteMode8i20);
  const ChannelStatus bad{0x0000C008};
  EXPECT_FALSE(bad.ok());
  EXPECT_TRUE(bad.timed_out());
  EXPECT_EQ(bad.describe(), "communication not ready, no remote ID, timeout");
  EXPECT_TRUE(ChannelStatus{0x80002001}.crc_error());
  EXPECT_EQ(sslbp::name_of_word(sslbp::kName8i20), "8I20");
}
