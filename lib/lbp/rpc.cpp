// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp/rpc.hpp"

#include <string>

#include "lbp/error.hpp"

namespace i20::lbp {
namespace {

bool data_in_table(const DataHeader& h) {
  return h.write && h.rpc_includes_data;
}

std::string where(unsigned number, std::size_t offset) {
  return "RPC " + std::to_string(number) + " at table offset " + std::to_string(offset);
}

}  // namespace

std::size_t RpcStep::stream_bytes() const {
  return header.write && !header.rpc_includes_data ? header.data_bytes() : 0;
}

std::size_t RpcStep::reply_bytes() const {
  return header.write ? 0 : header.data_bytes();
}

std::size_t RpcStep::stored_bytes() const {
  return 1 + header.address_bytes() + (data_in_table(header) ? header.data_bytes() : 0);
}

RpcList decode_rpc_list(ByteView table, unsigned number, std::size_t pitch) {
  if (number >= kRpcCount)
    throw UsageError("RPC number " + std::to_string(number) + " is out of range 0..63");
  std::size_t offset = number * pitch;
  RpcList list;
  while (true) {
    if (offset >= table.size())
      throw ProtocolError(where(number, offset) + ": list runs off the end of the " +
                          std::to_string(table.size()) + "-byte RPC table without a 0x00 terminator");
    const Byte b = table[offset];
    if (b == 0x00) {
      list.stored_bytes = offset + 1 - number * pitch;
      return list;
    }
    if (kind_of(b) != CommandKind::Data)
      throw ProtocolError(where(number, offset) + ": byte 0x" + to_hex(table.subspan(offset, 1)) +
                          " is not a data read/write command");
    RpcStep step;
    step.header = DataHeader::decode(b);
    const std::size_t need = step.stored_bytes();
    if (offset + need > table.size())
      throw ProtocolError(where(number, offset) + ": command is cut off by the end of the RPC table");
    std::size_t pos = offset + 1;
    if (step.header.has_address) {
      step.address = static_cast<std::uint16_t>(read_le(table.subspan(pos, 2)));
      pos += 2;
    }
    if (data_in_table(step.header)) {
      const auto data = table.subspan(pos, step.header.data_bytes());
      step.table_data.assign(data.begin(), data.end());
    }
    list.stream_bytes += step.stream_bytes();
    list.reply_bytes += step.reply_bytes();
    offset += need;
    list.steps.push_back(std::move(step));
  }
}

Bytes encode_rpc_list(const std::vector<RpcStep>& steps) {
  Bytes out;
  for (const auto& s : steps) {
    if (s.header.has_address != s.address.has_value())
      throw UsageError("RPC step: the AS bit and the presence of an address disagree");
    const std::size_t expected_data = data_in_table(s.header) ? s.header.data_bytes() : 0;
    if (s.table_data.size() != expected_data)
      throw UsageError("RPC step: stored data must be " + std::to_string(expected_data) + " bytes, not " +
                       std::to_string(s.table_data.size()));
    out.push_back(s.header.encode());
    if (s.address) append_le(out, *s.address, 2);
    out.insert(out.end(), s.table_data.begin(), s.table_data.end());
  }
  out.push_back(0x00);
  return out;
}

}  // namespace i20::lbp
