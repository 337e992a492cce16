// SPDX-License-Identifier: GPL-2.0-or-later
// The 8I20's RPC table with the RPCs it ships with for current (torque) mode
// (manual "RPC COMMANDS": "The 8I20 has some pre-loaded RPCs"; docs/facts.md s3: SSLBP's
// normal mode uses them). Their addresses come from the register map, so a card with a
// different map has a different table and discovery code can decode it.
//
// Layout (pitch 8, table 512 bytes = 64 RPCs):
//   RPC 0 (0x000): write ANGLE, write QSETPOINT   (4 stream bytes, reply: none)
//   RPC 1 (0x008): read BUSV, read TEMPERATURE    (reply 4 bytes)
//   RPC 2 (0x010): read FAULT, read STATUS        (reply 4 bytes)
//   RPC 3 (0x018..0x02A, spans slots 3-5): the whole SSLBP cycle: write ANGLE,
//          write QSETPOINT, read TEMPERATURE, BUSV, STATUS, FAULT (4 in, 8 out), in the
//          order of SSLBP's interface registers (LSW first).
//   all other slots: empty lists (a lone terminator).
// Every step is a 2-byte data access with a 2-byte address (header 0x65 write, 0x45 read).
#pragma once

#include <cstddef>

#include "lbp/bytes.hpp"
#include "lbp/local.hpp"
#include "sim/register_map.hpp"

namespace i20::sim {

inline constexpr std::size_t kRpcTableBytes = 512;

lbp::Bytes preloaded_rpc_table(const RegisterMap& map);

}  // namespace i20::sim
