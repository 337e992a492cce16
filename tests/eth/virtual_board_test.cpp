// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual card's LBP16 spaces, driven packet by packet without sockets.
#include "ethsim/virtual_board.hpp"

#include <gtest/gtest.h>

using namespace i20;
using namespace i20::ethsim;
using namespace std::chrono_literals;
namespace lbp16 = i20::lbp::lbp16;
using lbp16::Width;

namespace {

class EthVirtualBoard : public ::testing::Test {
 protected:
  Clock::time_point t0 = Clock::time_point{} + 1h;
  VirtualBoard board{VirtualBoardOptions{}, t0};

  std::optional<lbp::Bytes> send(const std::vector<lbp16::Command>& commands, Clock::duration at = 0s) {
    return board.handle(lbp16::encode_packet(commands), t0 + at);
  }
  std::vector<lbp::Bytes> transact(const std::vector<lbp16::Command>& commands) {
    const auto reply = send(commands);
    return lbp16::split_reply(commands, reply.value_or(lbp::Bytes{}));
  }
  std::uint64_t read16(std::uint8_t space, std::uint16_t address) {
    return lbp::read_le(transact({lbp16::read(space, address, Width::Bits16)})[0]);
  }
};

}  // namespace

TEST_F(EthVirtualBoard, AnswersTheElbpcomCookieRead) {
  EXPECT_EQ(board.handle(lbp::from_hex("01420001"), t0), lbp::from_hex("fecaaa55"));
}

TEST_F(EthVirtualBoard, IdentAreaAndIdromAreWhereHostMot2PutsThem) {
  const auto parts = transact({lbp16::read_hm2(0x0100, 4), lbp16::read_hm2(0x0400, 16)});
  const auto ident = lbp::hm2::IdentArea::parse(parts[0]);
  EXPECT_EQ(ident.config_name, "HOSTMOT2");
  EXPECT_EQ(ident.idrom_address, 0x400u);
  EXPECT_EQ(lbp::hm2::Idrom::parse(parts[1]).board_name, "MESA7I96");
}

TEST_F(EthVirtualBoard, EveryImplementedSpaceHasItsInfoArea) {
  for (std::uint8_t space : {0, 1, 2, 3, 4, 6, 7}) {
    const auto area = lbp16::InfoArea::parse(transact({lbp16::read_info(space, 0, 8)})[0]);
    EXPECT_TRUE(area.cookie_ok(space)) << int(space);
    EXPECT_FALSE(area.name.empty());
  }
  const auto hm2 = lbp16::InfoArea::parse(transact({lbp16::read_info(0, 0, 8)})[0]);
  EXPECT_TRUE(hm2.sizes.writable);
  EXPECT_EQ(hm2.sizes.type, lbp16::memtype::kRegister);
  EXPECT_TRUE(hm2.sizes.allows(Width::Bits32));
  EXPECT_EQ(hm2.ranges.range_bytes(), 65536u);
  const auto flash = lbp16::InfoArea::parse(transact({lbp16::read_info(3, 0, 8)})[0]);
  EXPECT_EQ(flash.sizes.type, lbp16::memtype::kFlash);
  EXPECT_EQ(flash.ranges.erase_log2, 16);
  EXPECT_FALSE(lbp16::InfoArea::parse(transact({lbp16::read_info(7, 0, 8)})[0]).sizes.writable);
  // Only 16-bit access is allowed to an info area.
  lbp16::Command wide = lbp16::read(0, 0, Width::Bits32, 1);
  wide.word.info_area = true;
  transact({wide});
  EXPECT_TRUE(board.status_register(status_reg::kErrors) & status_reg::kMemErrorBit);
}

TEST_F(EthVirtualBoard, Space7CarriesNameAndVersions) {
  const auto info = lbp16::BoardInfo::parse(transact({lbp16::read_board_info()})[0]);
  EXPECT_EQ(info.card_name, "7I96S");
  EXPECT_EQ(info.lbp16_version, 3);
  EXPECT_GT(info.firmware_version, 0);
  send({lbp16::write(7, 0, Width::Bits16, lbp::Bytes{'X', 'X'})});
  EXPECT_EQ(lbp16::BoardInfo::parse(transact({lbp16::read_board_info()})[0]).card_name, "7I96S");
  EXPECT_TRUE(board.status_register(status_reg::kErrors) & status_reg::kWriteErrorBit);
}

TEST_F(EthVirtualBoard, EepromWritesNeedTheEnableInTheSamePacket) {
  const lbp::Bytes ip = lbp::to_le(0xC0A80020u, 4);
  const auto write_ip = lbp16::write(lbp16::space::kEthernetEeprom, 0x20, Width::Bits16, ip);
  // Without the enable: refused.
  send({write_ip});
  EXPECT_EQ(board.eeprom_word(0x22), 0xC0A8);  // still 192.168.1.121
  EXPECT_EQ(board.eeprom_word(0x20), 0x0179);
  EXPECT_TRUE(board.status_register(status_reg::kErrors) & status_reg::kWriteErrorBit);
  // The manual's packet: 01D91A00025A 82C920002000A8C0.
  EXPECT_FALSE(board.handle(lbp::from_hex("01D91A00025A82C920002000A8C0"), t0));  // writes only: no reply
  EXPECT_EQ(board.eeprom_word(0x20), 0x0020);
  EXPECT_EQ(board.eeprom_word(0x22), 0xC0A8);
  // The enable is gone at the end of the packet.
  EXPECT_EQ(board.status_register(status_reg::kEepromWriteEnable), 0);
  send({lbp16::write(lbp16::space::kEthernetEeprom, 0x20, Width::Bits16, lbp::to_le(0x1111, 2))});
  EXPECT_EQ(board.eeprom_word(0x20), 0x0020);
  // The first 0x20 bytes are read only even with the enable.
  send({lbp16::enable_writes(2), lbp16::write(2, 0x10, Width::Bits16, lbp::to_le(0x4141, 2))});
  EXPECT_EQ(board.eeprom_word(0x10), 'I' << 8 | '7');
}

TEST_F(EthVirtualBoard, FlashIdReadWriteAndErase) {
  using lbp16::space::kFpgaFlash;
  EXPECT_EQ(lbp::read_le(transact({lbp16::read(kFpgaFlash, 8, Width::Bits32, 1, false)})[0]), 0x14u);
  const lbp::Bytes page = lbp16::bytes_of_words(std::vector<std::uint32_t>{1, 2, 3, 4});
  // Write needs 0x5A03; the trailing read commits and synchronises.
  const auto sync = transact({lbp16::enable_writes(kFpgaFlash),
                              lbp16::write(kFpgaFlash, 0, Width::Bits32, lbp::to_le(0xC000, 4), false),
                              lbp16::write(kFpgaFlash, 4, Width::Bits32, page, false),
                              lbp16::read(kFpgaFlash, 0, Width::Bits32, 1, false)});
  EXPECT_EQ(lbp::read_le(sync[3]), 0xC010u);
  const auto back = transact({lbp16::write(kFpgaFlash, 0, Width::Bits32, lbp::to_le(0xC000, 4), false),
                              lbp16::read(kFpgaFlash, 4, Width::Bits32, 5, false)});
  EXPECT_EQ(lbp16::words32(back[1]), (std::vector<std::uint32_t>{1, 2, 3, 4, 0xFFFFFFFF}));
  send({lbp16::enable_writes(kFpgaFlash),
        lbp16::write(kFpgaFlash, 0, Width::Bits32, lbp::to_le(0xC000, 4), false),
        lbp16::write(kFpgaFlash, 0xC, Width::Bits32, lbp::to_le(0, 4), false)});
  const auto erased = transact({lbp16::write(kFpgaFlash, 0, Width::Bits32, lbp::to_le(0xC000, 4), false),
                                lbp16::read(kFpgaFlash, 4, Width::Bits32, 1, false)});
  EXPECT_EQ(lbp::read_le(erased[1]), 0xFFFFFFFFu);
}

TEST_F(EthVirtualBoard, WaitMicrosecondsDelaysTheRestOfThePacket) {
  const Clock::time_point before = board.board_time();
  const auto parts = transact({lbp16::read(4, 0, Width::Bits16, 1, false),
                               lbp16::write(4, 2, Width::Bits16, lbp::to_le(500, 2), false),
                               lbp16::read(4, 0, Width::Bits16, 1, false)});
  EXPECT_EQ(board.board_time() - before, 500us);
  EXPECT_EQ(lbp::read_le(parts[2]) - lbp::read_le(parts[0]), 500u);
}

TEST_F(EthVirtualBoard, CountersAndScratch) {
  send({lbp16::write(6, 0x18, Width::Bits16, lbp::to_le(0xBEEF, 2))});
  EXPECT_EQ(read16(6, 0x18), 0xBEEF);
  EXPECT_EQ(board.status_register(status_reg::kRxUdp), 2);
  EXPECT_EQ(board.status_register(status_reg::kTxUdp), 1);  // the write-only packet got no reply
}

TEST_F(EthVirtualBoard, WrongWidthsAndMissingSpacesAreMemErrorsWithZeros) {
  const auto parts = transact({lbp16::read(0, 0x100, Width::Bits16, 2), lbp16::read(5, 0, Width::Bits16, 1)});
  EXPECT_EQ(parts[0], lbp::Bytes(4, 0));
  EXPECT_EQ(parts[1], lbp::Bytes(2, 0));
  EXPECT_TRUE(board.status_register(status_reg::kErrors) & status_reg::kMemErrorBit);
  EXPECT_EQ(board.stats().mem_errors, 2u);
}

TEST_F(EthVirtualBoard, TruncatedPacketIsAParseErrorAfterTheGoodCommands) {
  lbp::Bytes packet = lbp16::encode_packet(std::vector{lbp16::read_hm2(0x100)});
  packet.push_back(0x01);  // half a command word
  EXPECT_EQ(board.handle(packet, t0), lbp::from_hex("fecaaa55"));
  EXPECT_TRUE(board.status_register(status_reg::kErrors) & status_reg::kParseErrorBit);
  EXPECT_EQ(board.status_register(status_reg::kParseErrors), 1);
}

TEST_F(EthVirtualBoard, IdromIsReadOnlyOtherRegistersAreNot) {
  send({lbp16::write_hm2(0x0400, 0u), lbp16::write_hm2(0x1100, 0x7u)});
  EXPECT_EQ(board.hm2_register(0x0400), 3u);  // IDROM type
  EXPECT_EQ(board.hm2_register(0x1100), 7u);  // IOPORT DDR
}
