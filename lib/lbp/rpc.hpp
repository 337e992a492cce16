// SPDX-License-Identifier: GPL-2.0-or-later
// Stored RPC lists (manual, "RPC COMMANDS", "EXAMPLE RPC COMMAND LIST").
// RPC n starts at n * pitch in the RPC table; its list is a run of data read/write
// commands (header, optional 2-byte address, data only when the header has RID set and
// writes) ended by a 0x00 byte. A list may run past its pitch slot up to the table end.
#pragma once

#include <optional>
#include <vector>

#include "lbp/bytes.hpp"
#include "lbp/header.hpp"
#include "lbp/local.hpp"

namespace i20::lbp {

struct RpcStep {
  DataHeader header;
  std::optional<std::uint16_t> address{};  // present when header.has_address
  Bytes table_data{};                      // stored data: only for writes with RID

  // Data bytes this step takes from the serial stream (writes without RID).
  std::size_t stream_bytes() const;
  // Data bytes this step adds to the reply (reads).
  std::size_t reply_bytes() const;
  // Bytes the step occupies in the table.
  std::size_t stored_bytes() const;

  bool operator==(const RpcStep&) const = default;
};

struct RpcList {
  std::vector<RpcStep> steps;
  std::size_t stored_bytes = 0;  // including the terminator
  std::size_t stream_bytes = 0;  // data the RPC command must carry after its header
  std::size_t reply_bytes = 0;   // data the RPC returns, CRC excluded
};

// Decodes RPC `number` from the table. Throws ProtocolError if the list holds a byte
// that is not a data command, or runs off the end of the table without a terminator.
RpcList decode_rpc_list(ByteView table, unsigned number, std::size_t pitch = local::kRpcPitch);

// The stored form of a list, terminator included. Throws UsageError if a step is
// inconsistent (address presence vs AS bit, table data vs RID).
Bytes encode_rpc_list(const std::vector<RpcStep>& steps);

}  // namespace i20::lbp
