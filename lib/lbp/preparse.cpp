// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp/preparse.hpp"

#include "lbp/crc8.hpp"
#include "lbp/error.hpp"
#include "lbp/header.hpp"
#include "lbp/rpc.hpp"

namespace i20::lbp {

ShapeResult shape_of(Byte header, ByteView rpc_table, std::size_t rpc_pitch) {
  switch (kind_of(header)) {
    case CommandKind::Data: {
      const auto h = DataHeader::decode(header);
      return {
          true, {1 + h.address_bytes() + (h.write ? h.data_bytes() : 0), h.write ? 0 : h.data_bytes()}, {}};
    }
    case CommandKind::LocalRead: return {true, {1, 1}, {}};
    case CommandKind::LocalWrite: return {true, {1 + local::data_bytes(header), 0}, {}};
    case CommandKind::Rpc:
      try {
        const auto list = decode_rpc_list(rpc_table, rpc_number(header), rpc_pitch);
        return {true, {1 + list.stream_bytes, list.reply_bytes}, {}};
      } catch (const ProtocolError& e) {
        return {false, {}, e.what()};
      }
    case CommandKind::Terminator:
    case CommandKind::Invalid: break;
  }
  return {false, {}, "0x" + to_hex(ByteView(&header, 1)) + " is not an LBP command (command type 00)"};
}

CommandSplitter::Next CommandSplitter::next(ByteView rpc_table, std::size_t rpc_pitch) {
  Next result;
  if (buffer_.empty()) return result;
  const auto shape = shape_of(buffer_.front(), rpc_table, rpc_pitch);
  if (!shape.ok) {
    result.status = Status::Invalid;
    result.error = shape.error;
    return result;
  }
  const std::size_t wire = shape.shape.wire_command_bytes();
  if (buffer_.size() < wire) return result;
  result.status = Status::Frame;
  result.frame.command.assign(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(wire - 1));
  result.frame.shape = shape.shape;
  result.frame.received_crc = buffer_[wire - 1];
  result.frame.crc_ok = crc8(result.frame.command) == result.frame.received_crc;
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(wire));
  return result;
}

ReplySplitter::ReplySplitter(std::vector<std::size_t> reply_data_sizes)
    : sizes_(std::move(reply_data_sizes)) {}

void ReplySplitter::push(ByteView bytes) {
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

std::optional<ReplySplitter::Reply> ReplySplitter::next() {
  if (taken_ >= sizes_.size()) return std::nullopt;
  const std::size_t data = sizes_[taken_];
  if (buffer_.size() < data + 1) return std::nullopt;
  Reply r;
  r.data.assign(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(data));
  r.received_crc = buffer_[data];
  r.expected_crc = crc8(r.data);
  r.crc_ok = r.received_crc == r.expected_crc;
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(data + 1));
  ++taken_;
  return r;
}

std::size_t ReplySplitter::bytes_missing() const {
  std::size_t want = 0;
  for (std::size_t i = taken_; i < sizes_.size(); ++i) want += sizes_[i] + 1;
  return want > buffer_.size() ? want - buffer_.size() : 0;
}

std::size_t ReplySplitter::surplus_bytes() const {
  std::size_t want = 0;
  for (std::size_t i = taken_; i < sizes_.size(); ++i) want += sizes_[i] + 1;
  return buffer_.size() > want ? buffer_.size() - want : 0;
}

Bytes check_reply(ByteView wire, std::size_t data_bytes) {
  if (wire.size() != data_bytes + 1)
    throw ProtocolError("reply has " + std::to_string(wire.size()) + " bytes, expected " +
                        std::to_string(data_bytes) + " data bytes and a CRC");
  const auto data = wire.first(data_bytes);
  const Byte expected = crc8(data);
  if (wire.back() != expected)
    throw ProtocolError("reply CRC mismatch: received 0x" + to_hex(wire.last(1)) + ", computed 0x" +
                        to_hex(ByteView(&expected, 1)) + " over [" + to_hex(data) + "]");
  return Bytes(data.begin(), data.end());
}

}  // namespace i20::lbp
