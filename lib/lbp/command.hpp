// SPDX-License-Identifier: GPL-2.0-or-later
// Host-side LBP commands as values: the bytes to send (without CRC) and the number of
// reply data bytes they produce (the reply on the wire adds one CRC byte).
#pragma once

#include <cstdint>

#include "lbp/bytes.hpp"
#include "lbp/header.hpp"
#include "lbp/local.hpp"

namespace i20::lbp {

struct Command {
  Bytes bytes;                  // header, address, data: everything but the CRC
  std::size_t reply_bytes = 0;  // data bytes in the reply, CRC excluded
  // A barrier must be answered before anything else is sent: EEPROM writes take
  // milliseconds (docs/facts.md section 7) and resets drop whatever follows.
  bool barrier = false;

  bool operator==(const Command&) const = default;
};

// Data read of `size` bytes at `address` (AS=1), optionally leaving the pointer advanced.
Command read(std::uint16_t address, DataSize size, bool auto_increment = false);
// Data read at the current address pointer (AS=0).
Command read_at_pointer(DataSize size, bool auto_increment = true);
// Data write of the low `size` bytes of `value`, little endian.
Command write(std::uint16_t address, DataSize size, std::uint64_t value, bool auto_increment = false);
Command write_at_pointer(DataSize size, std::uint64_t value, bool auto_increment = true);
// Write of explicit bytes (1, 2, 4 or 8 of them; UsageError otherwise).
Command write_bytes(std::uint16_t address, ByteView data, bool auto_increment = false);

// Local read 0xC0..0xDF: one reply byte.
Command local_read(Byte command);
// Local write 0xE0..0xFE with its data byte.
Command local_write(Byte command, Byte data);
// 0xFF: resets the LBP parser, carries no data.
Command reset_parser();
// 0xFE 0x5A: resets the 8I20's processor (NV values are loaded into the working set).
Command reset_processor();
// NV access mode (0xEC).
Command set_nv_access(local::NvAccess mode);

// RPC n, with the data the stored list takes from the stream, producing reply_bytes.
Command rpc(unsigned number, ByteView stream_data, std::size_t reply_bytes);

// Wire form: the command bytes followed by their CRC-8.
Bytes frame(const Command& command);
// Wire form of a whole batch, back to back.
Bytes frame_all(const std::vector<Command>& commands);

}  // namespace i20::lbp
