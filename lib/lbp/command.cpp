// SPDX-License-Identifier: GPL-2.0-or-later
#include "lbp/command.hpp"

#include <string>

#include "lbp/crc8.hpp"
#include "error/error.hpp"

namespace i20::lbp {
namespace {

Command data_command(const DataHeader& header, std::optional<std::uint16_t> address, ByteView data) {
  Command c;
  c.bytes.push_back(header.encode());
  if (address) append_le(c.bytes, *address, 2);
  c.bytes.insert(c.bytes.end(), data.begin(), data.end());
  c.reply_bytes = header.write ? 0 : header.data_bytes();
  return c;
}

void require_local(Byte command, CommandKind kind, const char* what) {
  if (kind_of(command) != kind)
    throw UsageError("0x" + to_hex(ByteView(&command, 1)) + " is not a " + what + " command");
}

}  // namespace

Command read(std::uint16_t address, DataSize size, bool auto_increment) {
  return data_command({.auto_increment = auto_increment, .has_address = true, .size = size}, address, {});
}

Command read_at_pointer(DataSize size, bool auto_increment) {
  return data_command({.auto_increment = auto_increment, .size = size}, std::nullopt, {});
}

Command write(std::uint16_t address, DataSize size, std::uint64_t value, bool auto_increment) {
  const Bytes data = to_le(value, byte_count(size));
  return data_command({.write = true, .auto_increment = auto_increment, .has_address = true, .size = size},
                      address, data);
}

Command write_at_pointer(DataSize size, std::uint64_t value, bool auto_increment) {
  const Bytes data = to_le(value, byte_count(size));
  return data_command({.write = true, .auto_increment = auto_increment, .size = size}, std::nullopt, data);
}

Command write_bytes(std::uint16_t address, ByteView data, bool auto_increment) {
  const auto size = data_size_for(data.size());
  if (!size)
    throw UsageError("an LBP write carries 1, 2, 4 or 8 data bytes, not " + std::to_string(data.size()));
  return data_command({.write = true, .auto_increment = auto_increment, .has_address = true, .size = *size},
                      address, data);
}

Command local_read(Byte command) {
  require_local(command, CommandKind::LocalRead, "local read (0xC0..0xDF)");
  return Command{.bytes = {command}, .reply_bytes = 1};
}

Command local_write(Byte command, Byte data) {
  require_local(command, CommandKind::LocalWrite, "local write (0xE0..0xFE)");
  if (command == local::kResetParser) throw UsageError("0xFF carries no data byte: use reset_parser()");
  return Command{.bytes = {command, data}, .reply_bytes = 0};
}

Command reset_parser() {
  return Command{.bytes = {local::kResetParser}, .reply_bytes = 0};
}

Command reset_processor() {
  return Command{.bytes = {local::kResetProcessor, local::kResetKey}, .reply_bytes = 0, .barrier = true};
}

Command set_nv_access(local::NvAccess mode) {
  return local_write(local::kSetNvAccess, static_cast<Byte>(mode));
}

Command rpc(unsigned number, ByteView stream_data, std::size_t reply_bytes) {
  Command c;
  c.bytes.push_back(rpc_command(number));
  c.bytes.insert(c.bytes.end(), stream_data.begin(), stream_data.end());
  c.reply_bytes = reply_bytes;
  return c;
}

Bytes frame(const Command& command) {
  Bytes out = command.bytes;
  out.push_back(crc8(command.bytes));
  return out;
}

Bytes frame_all(const std::vector<Command>& commands) {
  Bytes out;
  for (const auto& c : commands) {
    out.insert(out.end(), c.bytes.begin(), c.bytes.end());
    out.push_back(crc8(c.bytes));
  }
  return out;
}

}  // namespace i20::lbp
