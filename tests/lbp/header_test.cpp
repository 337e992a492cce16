// SPDX-License-Identifier: GPL-2.0-or-later
// Command header layout: manual "LBP DATA READ/WRITE COMMAND" (0 1 WR RID AI AS DS1 DS0),
// "LBP RPC COMMAND" (1 0 RPC5..RPC0) and "LOCAL LBP COMMANDS".
#include "lbp/header.hpp"

#include <gtest/gtest.h>

#include "lbp/error.hpp"
#include "lbp/local.hpp"

using namespace i20;
using namespace i20::lbp;

TEST(Header, ManualExampleWrite4BytesWithAddressAndAutoInc) {
  // "LBPWrite: 2 add 4 data  0 1 1 0 1 1 1 0"
  const DataHeader h{.write = true, .auto_increment = true, .has_address = true, .size = DataSize::Four};
  EXPECT_EQ(h.encode(), 0b01101110);
}

TEST(Header, ManualExampleWrite2BytesAtPointer) {
  // "LBPWrite: 0 add 2 data  0 1 1 0 0 0 0 1"
  const DataHeader h{.write = true, .size = DataSize::Two};
  EXPECT_EQ(h.encode(), 0b01100001);
}

TEST(Header, ManualExampleRead8BytesWithAddress) {
  // "LBPRead: 2 add 8 data  0 1 0 0 0 1 1 1"
  const DataHeader h{.has_address = true, .size = DataSize::Eight};
  EXPECT_EQ(h.encode(), 0b01000111);
}

TEST(Header, EveryBitDecodesToItsField) {
  const auto h = DataHeader::decode(0b01111111);
  EXPECT_TRUE(h.write);
  EXPECT_TRUE(h.rpc_includes_data);
  EXPECT_TRUE(h.auto_increment);
  EXPECT_TRUE(h.has_address);
  EXPECT_EQ(h.size, DataSize::Eight);
  EXPECT_EQ(h.data_bytes(), 8u);
  EXPECT_EQ(h.address_bytes(), 2u);
  const auto r = DataHeader::decode(0x40);
  EXPECT_FALSE(r.write || r.rpc_includes_data || r.auto_increment || r.has_address);
  EXPECT_EQ(r.data_bytes(), 1u);
}

TEST(Header, AllDataHeadersRoundTrip) {
  for (unsigned b = 0x40; b <= 0x7F; ++b) EXPECT_EQ(DataHeader::decode(static_cast<Byte>(b)).encode(), b);
}

TEST(Header, DecodeRejectsNonDataTypes) {
  EXPECT_THROW(DataHeader::decode(0x00), ProtocolError);
  EXPECT_THROW(DataHeader::decode(0x3F), ProtocolError);
  EXPECT_THROW(DataHeader::decode(0x85), ProtocolError);
  EXPECT_THROW(DataHeader::decode(0xC1), ProtocolError);
}

TEST(Header, DataSizesAreOneTwoFourEight) {
  EXPECT_EQ(byte_count(DataSize::One), 1u);
  EXPECT_EQ(byte_count(DataSize::Two), 2u);
  EXPECT_EQ(byte_count(DataSize::Four), 4u);
  EXPECT_EQ(byte_count(DataSize::Eight), 8u);
  EXPECT_EQ(data_size_for(4), DataSize::Four);
  EXPECT_FALSE(data_size_for(0));
  EXPECT_FALSE(data_size_for(3));
  EXPECT_FALSE(data_size_for(16));
}

TEST(Header, KindsCoverTheWholeByteRange) {
  EXPECT_EQ(kind_of(0x00), CommandKind::Terminator);
  EXPECT_EQ(kind_of(0x01), CommandKind::Invalid);
  EXPECT_EQ(kind_of(0x3F), CommandKind::Invalid);
  EXPECT_EQ(kind_of(0x40), CommandKind::Data);
  EXPECT_EQ(kind_of(0x7F), CommandKind::Data);
  EXPECT_EQ(kind_of(0x80), CommandKind::Rpc);
  EXPECT_EQ(kind_of(0xBF), CommandKind::Rpc);
  EXPECT_EQ(kind_of(0xC0), CommandKind::LocalRead);
  EXPECT_EQ(kind_of(0xDF), CommandKind::LocalRead);
  EXPECT_EQ(kind_of(0xE0), CommandKind::LocalWrite);
  EXPECT_EQ(kind_of(0xFF), CommandKind::LocalWrite);
}

TEST(Header, RpcCommandIs80OrNumberBelow64) {
  EXPECT_EQ(rpc_command(0), 0x80);
  EXPECT_EQ(rpc_command(5), 0b10000101);  // manual: "RPC 5  1 0 0 0 0 1 0 1"
  EXPECT_EQ(rpc_command(63), 0xBF);
  EXPECT_THROW(rpc_command(64), UsageError);
  EXPECT_EQ(rpc_number(0x85), 5u);
  EXPECT_THROW(rpc_number(0x45), ProtocolError);
}

TEST(LocalCommands, ReadsCarryNoDataWritesCarryOneExcept0xFF) {
  for (unsigned c = 0xC0; c <= 0xDF; ++c) EXPECT_EQ(local::data_bytes(static_cast<Byte>(c)), 0u);
  for (unsigned c = 0xE0; c <= 0xFE; ++c) EXPECT_EQ(local::data_bytes(static_cast<Byte>(c)), 1u);
  EXPECT_EQ(local::data_bytes(0xFF), 0u);
}

TEST(LocalCommands, DocumentedCommandsHaveNamesReservedOnesDoNot) {
  EXPECT_EQ(local::name_of(local::kGetStatus), "get LBP status");
  EXPECT_EQ(local::name_of(local::kSetNvAccess), "set NV access mode");
  EXPECT_EQ(local::name_of(local::kGetCookie), "get LBP cookie");
  EXPECT_FALSE(local::name_of(0xC4));  // 0xC4..0xC9 reserved
  EXPECT_FALSE(local::name_of(0xE0));  // reserved
  EXPECT_FALSE(local::name_of(0xFB));  // 0xFB..0xFC reserved
  EXPECT_EQ(local::kGetCardName0, 0xD0);
  EXPECT_EQ(local::kResetProcessor, 0xFE);
  EXPECT_EQ(local::kResetKey, 0x5A);
  EXPECT_EQ(local::kCookie, 0x5A);
}
