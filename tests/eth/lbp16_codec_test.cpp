// SPDX-License-Identifier: GPL-2.0-or-later
// LBP16 codec against the examples of the 7I96S/7I92T manuals ("LBP16", "INFO AREA
// ACCESS", "SUPPORTED MEMORY SPACES", "ELBPCOM"), byte for byte.
#include <gtest/gtest.h>

#include "lbp/error.hpp"
#include "lbp16/lbp16.hpp"

using namespace i20;
using namespace i20::lbp;
using namespace i20::lbp::lbp16;

namespace {

Bytes hex(const std::string& text) {
  return from_hex(text);
}

Bytes packet(std::initializer_list<Command> commands) {
  const std::vector<Command> v(commands);
  return encode_packet(v);
}

}  // namespace

TEST(Lbp16Codec, CommandWordBitsFollowTheManualLayout) {
  // W A C M M M S S I N N N N N N N
  const CommandWord w{.write = true,
                      .has_address = true,
                      .info_area = false,
                      .space = 6,
                      .width = Width::Bits16,
                      .increment = false,
                      .count = 1};
  EXPECT_EQ(w.encode(), 0xD901);
  EXPECT_EQ(CommandWord::decode(0xD901), w);
  EXPECT_EQ(CommandWord::decode(0x4285).count, 5);
  EXPECT_TRUE(CommandWord::decode(0x4285).increment);
  EXPECT_EQ(CommandWord::decode(0x4285).width, Width::Bits32);
  EXPECT_TRUE(CommandWord::decode(0x6100 | 1).info_area);
  EXPECT_EQ(CommandWord::decode(0x1C00 | 1).space, 7);
}

TEST(Lbp16Codec, CountMustBe1To127) {
  EXPECT_THROW(read_hm2(0x400, 0), UsageError);
  EXPECT_THROW(read_hm2(0x400, 128), UsageError);
  EXPECT_NO_THROW(read_hm2(0x400, 127));
  EXPECT_THROW((CommandWord{.count = 0}.encode()), UsageError);
  EXPECT_THROW((CommandWord{.count = 200}.encode()), UsageError);
  // "A transfer count of 0 is an error": the card side refuses it too.
  EXPECT_THROW(CommandWord::decode(0x4200), ProtocolError);
  const Bytes too_many(128 * 4, 0);
  EXPECT_THROW(write(space::kHostMot2, 0x1000, Width::Bits32, too_many), UsageError);
}

TEST(Lbp16Codec, SpaceMustBe0To7) {
  EXPECT_THROW(read(8, 0, Width::Bits16), UsageError);
}

TEST(Lbp16Codec, ManualReadFiveIdromEntries) {
  EXPECT_EQ(packet({read_hm2(0x0400, 5)}), hex("85420004"));
  EXPECT_EQ(read_hm2(0x0400, 5).reply_bytes(), 20u);
}

TEST(Lbp16Codec, ManualWriteFourGpioPorts) {
  const std::uint32_t ports[] = {0xAAAAAAAA, 0xBBBBBBBB, 0xCCCCCCCC, 0xDDDDDDDD};
  EXPECT_EQ(packet({write_hm2(0x1000, ports)}), hex("84C20010AAAAAAAABBBBBBBBCCCCCCCCDDDDDDDD"));
  EXPECT_EQ(write_hm2(0x1000, ports).reply_bytes(), 0u);
}

TEST(Lbp16Codec, ManualEepromIpWriteNeedsTheEnableInTheSamePacket) {
  // 01D91A00025A: EEPROMWEna = 0x5A02; 82C920002000A8C0: two words at 0x20 (192.168.0.32).
  const Bytes ip = to_le(0xC0A80020u, 4);
  const Bytes bytes = packet({enable_writes(space::kEthernetEeprom),
                              write(space::kEthernetEeprom, 0x0020, Width::Bits16, ip, /*increment=*/true)});
  EXPECT_EQ(bytes, hex("01D91A00025A82C920002000A8C0"));
}

TEST(Lbp16Codec, ManualElbpcomSampleRun) {
  // >01420001 ; read hostmot2 cookie at 0x100 -> fecaaa55
  const Command cookie = read(space::kHostMot2, 0x0100, Width::Bits32, 1, false);
  EXPECT_EQ(packet({cookie}), hex("01420001"));
  const auto data = split_reply(std::span(&cookie, 1), hex("fecaaa55"));
  EXPECT_EQ(read_le(data[0]), 0x55AACAFEu);
  // >82492000 ; read EEPROM IP address at 0x0020 -> 450a5863 = 99.88.10.69
  const Command ip = read(space::kEthernetEeprom, 0x0020, Width::Bits16, 2, true);
  EXPECT_EQ(packet({ip}), hex("82492000"));
  EXPECT_EQ(read_le(split_reply(std::span(&ip, 1), hex("450a5863"))[0]), 0x63580A45u);
  // >01D91A00025A82C920000100a8C0 ; write EEPROM IP address with 192.168.0.1
  EXPECT_EQ(packet({enable_writes(space::kEthernetEeprom),
                    write(space::kEthernetEeprom, 0x0020, Width::Bits16, to_le(0xC0A80001u, 4))}),
            hex("01D91A00025A82C920000100a8C0"));
}

TEST(Lbp16Codec, ManualEthernetChipCiderRead) {
  EXPECT_EQ(packet({read(space::kEthernetChip, 0x00C0, Width::Bits16, 1, false)}), hex("0145C000"));
}

TEST(Lbp16Codec, ManualInfoAreaCommands) {
  // NN61LLHH, NN65LLHH, NN69LLHH, NN6DLLHH, NN79LLHH, NN7DLLHH (with address) ...
  const std::pair<std::uint8_t, std::uint8_t> with_address[] = {{0, 0x61}, {1, 0x65}, {2, 0x69},
                                                                {3, 0x6D}, {6, 0x79}, {7, 0x7D}};
  for (const auto& [space, high] : with_address) {
    const Command c = read_info(space, 0x0000, 8);
    EXPECT_EQ(packet({c}), (Bytes{0x88, high, 0x00, 0x00})) << "space " << int(space);
  }
  // ... and NN21, NN25, NN29, NN2D, NN39, NN3D at the pointer.
  const std::pair<std::uint8_t, std::uint8_t> at_pointer[] = {{0, 0x21}, {1, 0x25}, {2, 0x29},
                                                              {3, 0x2D}, {6, 0x39}, {7, 0x3D}};
  for (const auto& [space, high] : at_pointer) {
    Command c = read_at_pointer(space, Width::Bits16, 1, false);
    c.word.info_area = true;
    EXPECT_EQ(packet({c}), (Bytes{0x01, high})) << "space " << int(space);
  }
}

TEST(Lbp16Codec, ManualSpaceCommandHighBytes) {
  // Space 0 NN42/NNC2/NN02/NN82, space 4 NN51/NND1/NN11/NN91, space 6 NN59/NND9/NN19/NN99,
  // space 7 NN5D/NN1D.
  EXPECT_EQ(encode(read(0, 0, Width::Bits32, 1, false))[1], 0x42);
  EXPECT_EQ(encode(write(0, 0, Width::Bits32, Bytes(4), false))[1], 0xC2);
  EXPECT_EQ(encode(read_at_pointer(0, Width::Bits32, 1, false))[1], 0x02);
  EXPECT_EQ(encode(write_at_pointer(0, Width::Bits32, Bytes(4), false))[1], 0x82);
  EXPECT_EQ(encode(read(4, 0, Width::Bits16, 1, false))[1], 0x51);
  EXPECT_EQ(encode(write(4, 0, Width::Bits16, Bytes(2), false))[1], 0xD1);
  EXPECT_EQ(encode(read_at_pointer(4, Width::Bits16, 1, false))[1], 0x11);
  EXPECT_EQ(encode(write_at_pointer(4, Width::Bits16, Bytes(2), false))[1], 0x91);
  EXPECT_EQ(encode(read(6, 0, Width::Bits16, 1, false))[1], 0x59);
  EXPECT_EQ(encode(write_at_pointer(6, Width::Bits16, Bytes(2), false))[1], 0x99);
  EXPECT_EQ(encode(read(7, 0, Width::Bits16, 1, false))[1], 0x5D);
  EXPECT_EQ(encode(read_at_pointer(7, Width::Bits16, 1, false))[1], 0x1D);
}

TEST(Lbp16Codec, ManualFlashReadSequence) {
  // 01CE000056341200: FL_ADDR = 0x00123456; 404E0400: 0x40 doublewords from FL_DATA
  // without the increment bit; 400E: the next 0x40 at the pointer.
  const Command set_address = write(space::kFpgaFlash, 0x0000, Width::Bits32, to_le(0x00123456, 4), false);
  const Command first = read(space::kFpgaFlash, 0x0004, Width::Bits32, 0x40, false);
  const Command next = read_at_pointer(space::kFpgaFlash, Width::Bits32, 0x40, false);
  EXPECT_EQ(packet({set_address}), hex("01CE000056341200"));
  EXPECT_EQ(packet({first}), hex("404E0400"));
  EXPECT_EQ(packet({next}), hex("400E"));
  // Four of these in one packet: 1024 bytes back, "close to the maximum".
  const std::vector<Command> reads{first, next, next, next};
  EXPECT_EQ(reply_bytes(reads), 1024u);
  EXPECT_NO_THROW(encode_packet(reads));
}

TEST(Lbp16Codec, ManualFlashPageWriteAndSectorErase) {
  // 01D91A00035A: EEPROMWEna = 0x5A03; 01CE000000C00000: FL_ADDR = 0xC000;
  // 40CE0400 + 64 doublewords; 014E0000: read FL_ADDR for synchronisation.
  const Bytes page(256, 0xA5);
  const Bytes bytes = packet({enable_writes(space::kFpgaFlash),
                              write(space::kFpgaFlash, 0x0000, Width::Bits32, to_le(0xC000, 4), false),
                              write(space::kFpgaFlash, 0x0004, Width::Bits32, page, false),
                              read(space::kFpgaFlash, 0x0000, Width::Bits32, 1, false)});
  Bytes expected = hex("01D91A00035A01CE000000C0000040CE0400");
  expected.insert(expected.end(), page.begin(), page.end());
  const Bytes tail = hex("014E0000");
  expected.insert(expected.end(), tail.begin(), tail.end());
  EXPECT_EQ(bytes, expected);
  // Erase sector 0x00010000: 01CE0000 00000100, 01CE0C00 00000000.
  EXPECT_EQ(packet({write(space::kFpgaFlash, 0x0000, Width::Bits32, to_le(0x00010000, 4), false)}),
            hex("01CE000000000100"));
  EXPECT_EQ(packet({write(space::kFpgaFlash, 0x000C, Width::Bits32, to_le(0, 4), false)}),
            hex("01CE0C0000000000"));
}

TEST(Lbp16Codec, SeveralCommandsPerPacketAndTheirReplies) {
  const std::vector<Command> cmds{read_hm2(0x0100, 4), write_hm2(0x1000, 0x12345678u),
                                  read(space::kBoardInfo, 0x0010, Width::Bits16, 2)};
  EXPECT_EQ(reply_bytes(cmds), 16u + 4u);
  Bytes reply(20);
  for (std::size_t i = 0; i < reply.size(); ++i) reply[i] = static_cast<Byte>(i);
  const auto parts = split_reply(cmds, reply);
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].size(), 16u);
  EXPECT_TRUE(parts[1].empty());  // writes return nothing
  EXPECT_EQ(parts[2], (Bytes{16, 17, 18, 19}));
}

TEST(Lbp16Codec, ReplyOfTheWrongSizeIsRefused) {
  const std::vector<Command> cmds{read_hm2(0x0100, 1)};
  EXPECT_THROW(split_reply(cmds, Bytes(3)), ProtocolError);
  EXPECT_THROW(split_reply(cmds, Bytes(5)), ProtocolError);
}

TEST(Lbp16Codec, PacketSizeIsBoundedByOneUdpPayload) {
  std::vector<Command> cmds;
  for (int i = 0; i < 12; ++i) cmds.push_back(read_hm2(0, 127));  // 12 * 508 bytes of reply
  EXPECT_THROW(encode_packet(cmds), UsageError);
}

TEST(Lbp16Codec, ParseRequestRoundTripsAndStopsAtErrors) {
  const std::vector<Command> cmds{enable_writes(space::kEthernetEeprom), read_hm2(0x0400, 5),
                                  read_at_pointer(space::kBoardInfo, Width::Bits16, 3)};
  const Bytes wire = encode_packet(cmds);
  const auto parsed = parse_request(wire);
  EXPECT_FALSE(parsed.error);
  EXPECT_EQ(parsed.commands, cmds);

  Bytes truncated = wire;
  truncated.pop_back();  // the last command now lacks its high word byte
  const auto cut = parse_request(truncated);
  ASSERT_TRUE(cut.error);
  EXPECT_EQ(cut.commands.size(), 2u);

  const auto zero = parse_request(hex("00420001"));
  ASSERT_TRUE(zero.error);
  EXPECT_TRUE(zero.commands.empty());
}

TEST(Lbp16Codec, InfoAreaEncodesCookieSizesRangesAndName) {
  const InfoArea area{.cookie = 0x5A02,
                      .sizes = {.writable = true, .type = memtype::kEeprom, .access_mask = 0x02},
                      .ranges = {.erase_log2 = 0, .page_log2 = 0, .range_log2 = 7},
                      .address_pointer = 0x20,
                      .name = "EEPROM"};
  const Bytes bytes = area.encode();
  ASSERT_EQ(bytes.size(), kInfoAreaBytes);
  EXPECT_EQ(read_le(ByteView(bytes).subspan(2, 2)), 0x8E02u);  // W | type 0x0E | 16-bit
  const InfoArea back = InfoArea::parse(bytes);
  EXPECT_TRUE(back.cookie_ok(2));
  EXPECT_FALSE(back.cookie_ok(3));
  EXPECT_EQ(back.sizes, area.sizes);
  EXPECT_TRUE(back.sizes.allows(Width::Bits16));
  EXPECT_FALSE(back.sizes.allows(Width::Bits32));
  EXPECT_EQ(back.ranges.range_bytes(), 128u);
  EXPECT_EQ(back.name, "EEPROM");
  // Flash: erase 64K, page 256, 2 MB.
  const MemRanges flash{.erase_log2 = 16, .page_log2 = 8, .range_log2 = 21};
  EXPECT_EQ(MemRanges::decode(flash.encode()), flash);
}

TEST(Lbp16Codec, BoardInfoParsesSpace7) {
  Bytes bytes(board_info::kBytes, 0);
  const std::string name = "7I96S";
  std::copy(name.begin(), name.end(), bytes.begin());
  bytes[0x10] = 3;
  bytes[0x12] = 17;
  const BoardInfo info = BoardInfo::parse(bytes);
  EXPECT_EQ(info.card_name, "7I96S");
  EXPECT_EQ(info.lbp16_version, 3);
  EXPECT_EQ(info.firmware_version, 17);
  EXPECT_EQ(encode(read_board_info()), hex("8B5D0000"));
}
