// SPDX-License-Identifier: GPL-2.0-or-later
// The card-side LBP splitter (manual "FRAMING": pre-parsing) and the RPC list codec it
// relies on ("RPC COMMANDS"), fed an RPC table and a byte stream in arbitrary pieces.
//
// Input: [table choice][table bytes when fuzzed: 512][chunk length, chunk bytes]...
#include <cstddef>
#include <cstdint>

#include "fuzz_support.hpp"
#include "lbp/crc8.hpp"
#include "lbp/header.hpp"
#include "lbp/preparse.hpp"
#include "lbp/rpc.hpp"
#include "sim/register_map.hpp"
#include "sim/rpc_table.hpp"

namespace {

using namespace i20;

lbp::Bytes rpc_table(fuzz::Input& in) {
  if ((in.byte() & 1) == 0) {
    static const lbp::Bytes preloaded = sim::preloaded_rpc_table(sim::RegisterMap::builtin());
    return preloaded;
  }
  lbp::Bytes table = in.take(sim::kRpcTableBytes);
  table.resize(sim::kRpcTableBytes, 0x00);
  return table;
}

// Every list decodes or is refused with ProtocolError; one that decodes encodes back to
// the bytes it came from.
void check_rpc_lists(const lbp::Bytes& table) {
  for (unsigned n = 0; n < lbp::kRpcCount; ++n) {
    fuzz::expect_only_toolkit_errors([&] {
      const auto list = lbp::decode_rpc_list(table, n);
      const lbp::Bytes stored = lbp::encode_rpc_list(list.steps);
      fuzz::require(stored.size() == list.stored_bytes, "an RPC list re-encodes to its stored length");
      fuzz::require(std::equal(stored.begin(), stored.end(), table.begin() + n * lbp::local::kRpcPitch),
                    "an RPC list re-encodes to its stored bytes");
    });
  }
}

void split(const lbp::Bytes& table, fuzz::Input& in) {
  lbp::CommandSplitter splitter;
  while (!in.empty()) {
    splitter.push(in.take(in.byte() % 32 + 1));
    for (;;) {
      const std::size_t before = splitter.pending();
      const auto next = splitter.next(table);
      if (next.status == lbp::CommandSplitter::Status::NeedMore) break;
      if (next.status == lbp::CommandSplitter::Status::Invalid) {
        fuzz::require(splitter.pending() == before, "an invalid header leaves the buffer as it was");
        fuzz::require(!next.error.empty(), "an invalid header says why");
        splitter.clear();  // the device resynchronises; here: start over
        break;
      }
      const auto& f = next.frame;
      fuzz::require(!f.command.empty(), "a frame has a header");
      fuzz::require(f.command.size() == f.shape.command_bytes, "a frame is as long as its shape");
      fuzz::require(before - splitter.pending() == f.shape.wire_command_bytes(),
                    "a frame takes its bytes and CRC");
      fuzz::require(f.crc_ok == (lbp::crc8(f.command) == f.received_crc),
                    "crc_ok says whether the CRC matches");
      const auto shape = lbp::shape_of(f.command.front(), table);
      fuzz::require(shape.ok && shape.shape == f.shape, "the frame's shape is its header's");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Input in(data, size);
  const lbp::Bytes table = rpc_table(in);
  check_rpc_lists(table);
  fuzz::expect_only_toolkit_errors([&] { split(table, in); });
  return 0;
}
