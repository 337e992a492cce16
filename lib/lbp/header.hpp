// SPDX-License-Identifier: GPL-2.0-or-later
// LBP command header bytes (manual, "LBP DATA READ/WRITE COMMAND", "LBP RPC COMMAND",
// "LOCAL LBP COMMANDS").
//
//   data read/write: 0 1 WR RID AI AS DS1 DS0
//   RPC:             1 0 RPC5..RPC0
//   local:           1 1 x x x x x x   (0xC0..0xDF read one byte, 0xE0..0xFF write)
#pragma once

#include <cstddef>
#include <optional>

#include "lbp/bytes.hpp"

namespace i20::lbp {

enum class CommandKind {
  Terminator,  // 0x00: ends a stored RPC list
  Invalid,     // 0x01..0x3F: command type 00b is not defined
  Data,        // 0x40..0x7F
  Rpc,         // 0x80..0xBF
  LocalRead,   // 0xC0..0xDF
  LocalWrite,  // 0xE0..0xFF
};

CommandKind kind_of(Byte header);

// DS1..DS0: 00b = 1 byte, 01b = 2, 10b = 4, 11b = 8.
enum class DataSize : Byte { One = 0, Two = 1, Four = 2, Eight = 3 };

std::size_t byte_count(DataSize size);
// The DataSize for 1, 2, 4 or 8 bytes; nullopt for any other count.
std::optional<DataSize> data_size_for(std::size_t bytes);

struct DataHeader {
  bool write = false;
  bool rpc_includes_data = false;  // RID: data comes from the stored RPC, not from the stream
  bool auto_increment = false;     // AI: address pointer += data size after the command
  bool has_address = false;        // AS: a 2-byte address follows the header
  DataSize size = DataSize::One;

  std::size_t data_bytes() const { return byte_count(size); }
  // Bytes of address carried in the command (0 or 2).
  std::size_t address_bytes() const { return has_address ? 2 : 0; }

  Byte encode() const;
  // Throws ProtocolError if the byte is not a data read/write command (type must be 01b).
  static DataHeader decode(Byte header);

  bool operator==(const DataHeader&) const = default;
};

inline constexpr unsigned kRpcCount = 64;

// 0x80 | n. Throws UsageError for n >= 64.
Byte rpc_command(unsigned number);
// RPC number of an RPC header. Throws ProtocolError if the byte is not an RPC command.
unsigned rpc_number(Byte header);

}  // namespace i20::lbp
