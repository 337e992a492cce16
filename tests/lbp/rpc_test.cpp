// SPDX-License-Identifier: GPL-2.0-or-later
// Manual "EXAMPLE RPC COMMAND LIST": RPC5 at 0x0028 writes two stream bytes to 0x10 and
// reads two bytes at 0x12, in 7 stored bytes.
#include "lbp/rpc.hpp"

#include <gtest/gtest.h>

#include "lbp/error.hpp"

using namespace i20;
using namespace i20::lbp;

namespace {
const Bytes kManualRpc5List{0x65, 0x10, 0x00, 0x45, 0x12, 0x00, 0x00};

Bytes table_with_rpc5() {
  Bytes table(0x100, 0x00);
  std::copy(kManualRpc5List.begin(), kManualRpc5List.end(), table.begin() + 0x28);
  return table;
}
}  // namespace

TEST(Rpc, ManualListEncodesByteForByte) {
  const std::vector<RpcStep> steps{
      {.header = {.write = true, .has_address = true, .size = DataSize::Two}, .address = 0x0010},
      {.header = {.has_address = true, .size = DataSize::Two}, .address = 0x0012},
  };
  EXPECT_EQ(encode_rpc_list(steps), kManualRpc5List);
}

TEST(Rpc, ManualListDecodesFromPitchBoundary) {
  const auto list = decode_rpc_list(table_with_rpc5(), 5);
  ASSERT_EQ(list.steps.size(), 2u);
  EXPECT_EQ(list.stored_bytes, 7u);
  EXPECT_EQ(list.stream_bytes, 2u);  // the 2 data bytes of command 1 come from the host
  EXPECT_EQ(list.reply_bytes, 2u);   // command 2 reads 2 bytes
  EXPECT_EQ(list.steps[0].address, 0x0010);
  EXPECT_TRUE(list.steps[0].header.write);
  EXPECT_EQ(list.steps[1].address, 0x0012);
}

TEST(Rpc, EmptySlotIsAnEmptyList) {
  const auto list = decode_rpc_list(table_with_rpc5(), 0);
  EXPECT_TRUE(list.steps.empty());
  EXPECT_EQ(list.stored_bytes, 1u);
}

TEST(Rpc, StoredDataWithRidComesFromTheTable) {
  const std::vector<RpcStep> steps{
      {.header = {.write = true, .rpc_includes_data = true, .has_address = true, .size = DataSize::Two},
       .address = 0x0100,
       .table_data = {0x34, 0x12}}};
  const auto stored = encode_rpc_list(steps);
  EXPECT_EQ(stored, (Bytes{0x75, 0x00, 0x01, 0x34, 0x12, 0x00}));
  Bytes table(16, 0);
  std::copy(stored.begin(), stored.end(), table.begin() + 8);
  const auto list = decode_rpc_list(table, 1);
  EXPECT_EQ(list.stream_bytes, 0u);
  EXPECT_EQ(list.steps[0].table_data, (Bytes{0x34, 0x12}));
}

TEST(Rpc, ListsMayCrossThePitchBoundary) {
  Bytes table(24, 0);
  const Bytes list{0x45, 0x00, 0x01, 0x45, 0x02, 0x01, 0x45, 0x04, 0x01, 0x00};  // 10 bytes > pitch 8
  std::copy(list.begin(), list.end(), table.begin());
  const auto decoded = decode_rpc_list(table, 0);
  EXPECT_EQ(decoded.steps.size(), 3u);
  EXPECT_EQ(decoded.reply_bytes, 6u);
}

TEST(Rpc, RejectsListsWithoutTerminatorOrWithForeignBytes) {
  Bytes table(8, 0x45);  // reads forever, then the table ends
  EXPECT_THROW(decode_rpc_list(table, 0), ProtocolError);
  Bytes local_inside{0xC1, 0x00};
  EXPECT_THROW(decode_rpc_list(local_inside, 0), ProtocolError);
  Bytes cut{0x45, 0x10};  // address cut off
  EXPECT_THROW(decode_rpc_list(cut, 0), ProtocolError);
  EXPECT_THROW(decode_rpc_list(Bytes(8, 0), 1), ProtocolError);  // slot beyond the table
  EXPECT_THROW(decode_rpc_list(Bytes(8, 0), 64), UsageError);
}

TEST(Rpc, EncodeRejectsInconsistentSteps) {
  EXPECT_THROW(encode_rpc_list({{.header = {.has_address = true}}}), UsageError);
  EXPECT_THROW(encode_rpc_list({{.header = {.write = true, .rpc_includes_data = true}}}), UsageError);
}
