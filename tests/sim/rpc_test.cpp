// SPDX-License-Identifier: GPL-2.0-or-later
// Manual "RPC COMMANDS", "EXAMPLE RPC COMMAND LIST"; docs/facts.md s3 (the preloaded RPCs
// name the addresses of ANGLE, QSETPOINT, BUSV, TEMPERATURE, FAULT and STATUS).
#include "lbp/rpc.hpp"

#include "bench.hpp"
#include "sim/rpc_table.hpp"

namespace i20::sim::test {
namespace {

// Reads the whole RPC table over LBP, as discovery code would.
lbp::Bytes read_table(Bench& b) {
  b.send("EA 01");
  lbp::Bytes table;
  b.send("F8 00");
  b.send("F9 00");
  const unsigned size = b.local(0xDD) | (b.local(0xDE) << 8);
  for (unsigned i = 0; i < size; i += 8) {
    const lbp::Bytes out = b.send("4B");  // read 8 at the pointer, AI
    EXPECT_EQ(out.size(), 9u);
    table.insert(table.end(), out.begin(), out.begin() + 8);
  }
  b.send("EA 00");
  return table;
}

std::vector<std::uint16_t> addresses(const lbp::Bytes& table, unsigned rpc) {
  std::vector<std::uint16_t> out;
  for (const auto& s : lbp::decode_rpc_list(table, rpc).steps) out.push_back(s.address.value());
  return out;
}

TEST(SimRpc, PreloadedTableNamesTheMapsAddresses) {
  Bench b;
  const auto table = read_table(b);
  ASSERT_EQ(table.size(), kRpcTableBytes);
  // RPC 0 written out by hand: 65 0C 08 65 0E 08 00 (write ANGLE, write QSETPOINT).
  EXPECT_EQ(lbp::Bytes(table.begin(), table.begin() + 7), lbp::from_hex("65 0C 08 65 0E 08 00"));
  const auto& m = b.card.amplifier().map();
  EXPECT_EQ(addresses(table, 0),
            (std::vector<std::uint16_t>{m.at("ANGLE").address, m.at("QSETPOINT").address}));
  EXPECT_EQ(addresses(table, 1),
            (std::vector<std::uint16_t>{m.at("BUSV").address, m.at("TEMPERATURE").address}));
  EXPECT_EQ(addresses(table, 2), (std::vector<std::uint16_t>{m.at("FAULT").address, m.at("STATUS").address}));
  const auto full = lbp::decode_rpc_list(table, 3);
  EXPECT_EQ(full.stream_bytes, 4u);
  EXPECT_EQ(full.reply_bytes, 8u);
  EXPECT_EQ(lbp::decode_rpc_list(table, 10).steps.size(), 0u) << "unused slots are empty lists";
}

TEST(SimRpc, ADifferentMapGivesADifferentTable) {
  DeviceOptions o;
  o.map = RegisterMap::builtin().shuffled(11);
  Bench b(o);
  const auto table = read_table(b);
  const auto& m = b.card.amplifier().map();
  EXPECT_NE(m.at("FAULT").address, RegisterMap::builtin().at("FAULT").address);
  EXPECT_EQ(addresses(table, 2), (std::vector<std::uint16_t>{m.at("FAULT").address, m.at("STATUS").address}));
  EXPECT_NE(table, preloaded_rpc_table(RegisterMap::builtin()));
}

TEST(SimRpc, TableIsHiddenWithoutRpcmemAccess) {
  Bench b;
  EXPECT_EQ(b.send("47 00 00"), reply("00 00 00 00 00 00 00 00")) << "RAM, not the table";
  b.send("EA 01");
  EXPECT_EQ(b.send("47 00 00"), reply("65 0C 08 65 0E 08 00 00"));
}

TEST(SimRpc, ReadBusvAndTemperature) {
  Bench b;  // 320.00 V, 35.00 C
  EXPECT_EQ(b.send("81"), reply("00 7D AC 0D"));
}

TEST(SimRpc, WriteAngleAndQsetpointFromTheStream) {
  Bench b;
  EXPECT_EQ(b.send("80 00 40 F6 FF"), lbp::Bytes{0x00});
  EXPECT_EQ(b.read("ANGLE"), 0x4000u);
  EXPECT_EQ(b.read("QSETPOINT"), 0xFFF6u);  // -10
}

TEST(SimRpc, WholeCycleRpc) {
  Bench b;
  b.card.world().settings().enable = false;
  const auto out = b.send("83 34 12 64 00");
  // TEMPERATURE, BUSV, STATUS (EXTR + no enable), FAULT (no enable).
  EXPECT_EQ(out, reply("AC 0D 00 7D 40 01 02 00"));
  EXPECT_EQ(b.read("ANGLE"), 0x1234u);
  EXPECT_EQ(b.read("QSETPOINT"), 100u);
}

TEST(SimRpc, ManualExampleRpc5WithStreamData) {
  Bench b;
  b.send("EA 01");
  // Write 2 at 0x10 (data from host), read 2 at 0x12, terminator: at 0x28 = RPC 5.
  EXPECT_EQ(b.send("6E 28 00 65 10 00 45"), lbp::Bytes{0x00});
  EXPECT_EQ(b.send("6A 12 00 00 00"), lbp::Bytes{0x00});  // 4 at the pointer (0x2C), AI
  b.send("EA 00");
  b.card.amplifier().write_ram(0x12, lbp::Bytes{0x9A, 0xBC});
  // RPC 5 with the manual's data bytes 0x55 0xCC.
  EXPECT_EQ(b.send("85 55 CC"), reply("9A BC"));
  EXPECT_EQ(b.read(0x10), 0xCC55u);
}

TEST(SimRpc, RidTakesDataFromTheTable) {
  Bench b;
  b.send("EA 01");
  // RPC 6 at 0x30: 75 20 00 11 22 (write 2 at 0x20, RID data 11 22), 45 20 00, 00.
  b.send("6F 30 00 75 20 00 11 22 45 20 00");
  b.send("68 00");  // the terminator at the pointer (0x38)
  b.send("EA 00");
  EXPECT_EQ(b.send("86"), reply("11 22")) << "no stream bytes: the data is stored";
}

TEST(SimRpc, TableWritesNeedRpcmemAccess) {
  Bench b;
  b.send("6E 28 00 65 10 00 45");  // RPCMEM off: plain RAM
  EXPECT_EQ(b.send("85"), lbp::Bytes{0x00}) << "RPC 5 is still empty";
  b.send("EA 01");
  EXPECT_EQ(b.send("44 28 00"), reply("00"));
  b.send("E1 00");
  EXPECT_EQ(b.send("66 FE 01 01 02 03 04"), lbp::Bytes{0x00}) << "past the table end";
  EXPECT_TRUE(b.local(0xC1) & lbp::local::kStatusInvalidWrite);
}

TEST(SimRpc, ResetRestoresThePreloadedTable) {
  Bench b;
  b.send("EA 01");
  b.send("6E 00 00 00 00 00 00");
  b.send("EA 00");
  EXPECT_EQ(b.send("80"), lbp::Bytes{0x00}) << "RPC 0 is now an empty list: no stream bytes";
  b.send("FE 5A");
  b.wait(2ms);
  b.send("EA 01");
  EXPECT_EQ(b.send("47 00 00"), reply("65 0C 08 65 0E 08 00 00"));
}

}  // namespace
}  // namespace i20::sim::test
