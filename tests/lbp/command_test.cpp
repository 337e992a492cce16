// SPDX-License-Identifier: GPL-2.0-or-later
// Byte-for-byte reproduction of the manual's "EXAMPLE LBP COMMANDS".
#include "lbp/command.hpp"

#include <gtest/gtest.h>

#include "lbp/crc8.hpp"
#include "error/error.hpp"

using namespace i20;
using namespace i20::lbp;

TEST(Command, ManualWrite4BytesAt0x0010WithAutoInc) {
  const auto c = write_bytes(0x0010, Bytes{0xAA, 0xBB, 0xCC, 0xDD}, /*auto_increment=*/true);
  EXPECT_EQ(c.bytes, (Bytes{0x6E, 0x10, 0x00, 0xAA, 0xBB, 0xCC, 0xDD}));
  EXPECT_EQ(c.reply_bytes, 0u);
  // The same command from a 32-bit value: little endian puts 0xAA at the lower address.
  EXPECT_EQ(write(0x0010, DataSize::Four, 0xDDCCBBAA, true).bytes, c.bytes);
}

TEST(Command, ManualContinuationWrite2BytesAtPointer) {
  const auto c = write_at_pointer(DataSize::Two, 0xFFEE, /*auto_increment=*/false);
  EXPECT_EQ(c.bytes, (Bytes{0x61, 0xEE, 0xFF}));
}

TEST(Command, ManualRead8BytesAt0x0010) {
  const auto c = read(0x0010, DataSize::Eight);
  EXPECT_EQ(c.bytes, (Bytes{0x47, 0x10, 0x00}));
  EXPECT_EQ(c.reply_bytes, 8u);
}

TEST(Command, FrameAppendsCrcOverTheWholeCommand) {
  const auto c = read(0x0010, DataSize::Eight);
  const auto wire = frame(c);
  ASSERT_EQ(wire.size(), 4u);
  EXPECT_EQ(wire.back(), crc8(Bytes{0x47, 0x10, 0x00}));
  EXPECT_EQ(crc8(wire), 0x00);
}

TEST(Command, FrameAllIsBackToBack) {
  const std::vector<Command> batch{read(2, DataSize::Two), local_read(local::kGetCookie)};
  const auto wire = frame_all(batch);
  Bytes expected = frame(batch[0]);
  const auto second = frame(batch[1]);
  expected.insert(expected.end(), second.begin(), second.end());
  EXPECT_EQ(wire, expected);
}

TEST(Command, LocalReadsReturnOneByte) {
  const auto c = local_read(local::kGetCardName0);
  EXPECT_EQ(c.bytes, (Bytes{0xD0}));
  EXPECT_EQ(c.reply_bytes, 1u);
  EXPECT_THROW(local_read(0xE1), UsageError);
}

TEST(Command, LocalWritesCarryOneDataByte) {
  EXPECT_EQ(local_write(local::kSetStatus, 0).bytes, (Bytes{0xE1, 0x00}));
  EXPECT_EQ(set_nv_access(local::NvAccess::Eeprom).bytes, (Bytes{0xEC, 0x01}));
  EXPECT_EQ(set_nv_access(local::NvAccess::Ram).bytes, (Bytes{0xEC, 0x00}));
  EXPECT_THROW(local_write(0xC1, 0), UsageError);
  EXPECT_THROW(local_write(0xFF, 0), UsageError);
}

TEST(Command, ResetNeedsTheKeyAndIsABarrier) {
  const auto c = reset_processor();
  EXPECT_EQ(c.bytes, (Bytes{0xFE, 0x5A}));
  EXPECT_TRUE(c.barrier);
  EXPECT_EQ(reset_parser().bytes, (Bytes{0xFF}));
}

TEST(Command, WriteBytesRejectsSizesTheHeaderCannotExpress) {
  EXPECT_THROW(write_bytes(0, Bytes{1, 2, 3}, false), UsageError);
  EXPECT_THROW(write_bytes(0, Bytes{}, false), UsageError);
  EXPECT_NO_THROW(write_bytes(0, Bytes(8, 0), false));
}

TEST(Command, ManualRpc5DataStreamIsThreeBytes) {
  // "The data stream for this RPC would consist of these 3 bytes": 0x85, 0x55, 0xCC.
  const auto c = rpc(5, Bytes{0x55, 0xCC}, 2);
  EXPECT_EQ(c.bytes, (Bytes{0x85, 0x55, 0xCC}));
  EXPECT_EQ(c.reply_bytes, 2u);
}
