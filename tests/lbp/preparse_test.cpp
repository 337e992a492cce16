// SPDX-License-Identifier: GPL-2.0-or-later
// Setup-mode framing by pre-parsing (manual "FRAMING"): command and reply lengths from
// the header (and the RPC table); stream splitting with CRC checks; reply parsing.
#include "lbp/preparse.hpp"

#include <gtest/gtest.h>

#include "lbp/command.hpp"
#include "lbp/crc8.hpp"
#include "lbp/error.hpp"

using namespace i20;
using namespace i20::lbp;

namespace {
Bytes rpc5_table() {
  Bytes table(0x40, 0x00);
  const Bytes list{0x65, 0x10, 0x00, 0x45, 0x12, 0x00, 0x00};
  std::copy(list.begin(), list.end(), table.begin() + 0x28);
  return table;
}
}  // namespace

TEST(Shape, ManualExamples) {
  EXPECT_EQ(shape_of(0x6E, {}).shape, (Shape{7, 0}));            // header, 2 address, 4 data
  EXPECT_EQ(shape_of(0x61, {}).shape, (Shape{3, 0}));            // header, 2 data
  EXPECT_EQ(shape_of(0x47, {}).shape, (Shape{3, 8}));            // header, 2 address; 8 back
  EXPECT_EQ(shape_of(0x85, rpc5_table()).shape, (Shape{3, 2}));  // RPC5 + 2 stream bytes; 2 back
}

TEST(Shape, EveryDataHeader) {
  for (unsigned b = 0x40; b <= 0x7F; ++b) {
    const auto h = DataHeader::decode(static_cast<Byte>(b));
    const auto s = shape_of(static_cast<Byte>(b), {});
    ASSERT_TRUE(s.ok);
    EXPECT_EQ(s.shape.command_bytes, 1 + (h.has_address ? 2 : 0) + (h.write ? h.data_bytes() : 0)) << b;
    EXPECT_EQ(s.shape.reply_bytes, h.write ? 0 : h.data_bytes()) << b;
  }
}

TEST(Shape, LocalCommands) {
  EXPECT_EQ(shape_of(0xC1, {}).shape, (Shape{1, 1}));
  EXPECT_EQ(shape_of(0xDF, {}).shape, (Shape{1, 1}));
  EXPECT_EQ(shape_of(0xEC, {}).shape, (Shape{2, 0}));
  EXPECT_EQ(shape_of(0xFE, {}).shape, (Shape{2, 0}));
  EXPECT_EQ(shape_of(0xFF, {}).shape, (Shape{1, 0}));
}

TEST(Shape, InvalidHeadersAndBrokenRpcsAreReported) {
  EXPECT_FALSE(shape_of(0x00, {}).ok);
  EXPECT_FALSE(shape_of(0x12, {}).ok);
  const auto broken = shape_of(0x80, Bytes(8, 0x45));
  EXPECT_FALSE(broken.ok);
  EXPECT_NE(broken.error.find("RPC 0"), std::string::npos);
}

TEST(Shape, WireLengthsAddTheCrc) {
  const Shape s{3, 8};
  EXPECT_EQ(s.wire_command_bytes(), 4u);
  EXPECT_EQ(s.wire_reply_bytes(), 9u);
}

TEST(CommandSplitter, CutsTheManualSequenceIntoCommands) {
  const std::vector<Command> batch{write_bytes(0x10, Bytes{0xAA, 0xBB, 0xCC, 0xDD}, true),
                                   write_at_pointer(DataSize::Two, 0xFFEE, false),
                                   read(0x10, DataSize::Eight), rpc(5, Bytes{0x55, 0xCC}, 2)};
  CommandSplitter splitter;
  splitter.push(frame_all(batch));
  const auto table = rpc5_table();
  for (const auto& c : batch) {
    const auto n = splitter.next(table);
    ASSERT_EQ(n.status, CommandSplitter::Status::Frame);
    EXPECT_EQ(n.frame.command, c.bytes);
    EXPECT_TRUE(n.frame.crc_ok);
    EXPECT_EQ(n.frame.shape.reply_bytes, c.reply_bytes);
  }
  EXPECT_EQ(splitter.next(table).status, CommandSplitter::Status::NeedMore);
  EXPECT_EQ(splitter.pending(), 0u);
}

TEST(CommandSplitter, WaitsForTruncatedCommandsAcrossGaps) {
  const auto wire = frame(read(0x10, DataSize::Eight));
  CommandSplitter splitter;
  for (std::size_t i = 0; i + 1 < wire.size(); ++i) {
    splitter.push(ByteView(&wire[i], 1));
    EXPECT_EQ(splitter.next({}).status, CommandSplitter::Status::NeedMore);
  }
  splitter.push(ByteView(&wire.back(), 1));
  EXPECT_EQ(splitter.next({}).status, CommandSplitter::Status::Frame);
}

TEST(CommandSplitter, FlagsCorruptedCommands) {
  auto wire = frame(write(0x0028, DataSize::Two, 36000));
  wire[3] ^= 0x01;  // corrupt a data byte
  CommandSplitter splitter;
  splitter.push(wire);
  const auto n = splitter.next({});
  ASSERT_EQ(n.status, CommandSplitter::Status::Frame);
  EXPECT_FALSE(n.frame.crc_ok);
}

TEST(CommandSplitter, ReportsGarbageWithoutConsumingIt) {
  CommandSplitter splitter;
  splitter.push(Bytes{0x01, 0x02});
  const auto n = splitter.next({});
  EXPECT_EQ(n.status, CommandSplitter::Status::Invalid);
  EXPECT_FALSE(n.error.empty());
  EXPECT_EQ(splitter.pending(), 2u);
  splitter.clear();
  EXPECT_EQ(splitter.pending(), 0u);
}

TEST(ReplySplitter, SplitsPipelinedRepliesByExpectedLength) {
  const Bytes r1{0x5A};
  const Bytes r2{0xA0, 0x8C};
  Bytes wire = r1;
  wire.push_back(crc8(r1));
  wire.push_back(0x00);  // a write's reply: CRC only, always 0x00
  wire.insert(wire.end(), r2.begin(), r2.end());
  wire.push_back(crc8(r2));
  ReplySplitter splitter({1, 0, 2});
  EXPECT_EQ(splitter.bytes_missing(), 6u);
  splitter.push(ByteView(wire).first(3));
  auto a = splitter.next();
  ASSERT_TRUE(a);
  EXPECT_EQ(a->data, r1);
  EXPECT_TRUE(a->crc_ok);
  auto b = splitter.next();
  ASSERT_TRUE(b);
  EXPECT_TRUE(b->data.empty());
  EXPECT_TRUE(b->crc_ok);
  EXPECT_FALSE(splitter.next());
  splitter.push(ByteView(wire).subspan(3));
  auto c = splitter.next();
  ASSERT_TRUE(c);
  EXPECT_EQ(c->data, r2);
  EXPECT_EQ(splitter.bytes_missing(), 0u);
  EXPECT_EQ(splitter.replies_taken(), 3u);
}

TEST(ReplySplitter, FlagsBadCrcAndSurplus) {
  ReplySplitter splitter({1});
  splitter.push(Bytes{0x5A, 0x00, 0x77});
  const auto r = splitter.next();
  ASSERT_TRUE(r);
  EXPECT_FALSE(r->crc_ok);
  EXPECT_EQ(r->expected_crc, crc8(Bytes{0x5A}));
  EXPECT_EQ(splitter.surplus_bytes(), 1u);
}

TEST(CheckReply, AcceptsGoodRejectsShortLongAndCorrupt) {
  const Bytes data{0xA0, 0x8C};
  Bytes wire = data;
  wire.push_back(crc8(data));
  EXPECT_EQ(check_reply(wire, 2), data);
  EXPECT_THROW(check_reply(ByteView(wire).first(2), 2), ProtocolError);
  Bytes longer = wire;
  longer.push_back(0);
  EXPECT_THROW(check_reply(longer, 2), ProtocolError);
  wire[0] ^= 0x80;
  EXPECT_THROW(check_reply(wire, 2), ProtocolError);
  EXPECT_EQ(check_reply(Bytes{0x00}, 0), Bytes{});
}
