// SPDX-License-Identifier: GPL-2.0-or-later
// How one 8I20 LBP command travels through SSLBP's setup-mode passthrough (8I20 manual,
// "SETUP MODE OPERATION"; docs/facts.md section 5):
//
//   data read/write with a 2-byte address, 1/2/4 data bytes:
//       CS = header << 24 | address, INTERFACE0 = write data (right justified)
//   local read 0xC0..0xDF / local write 0xE0..0xFE (0xEC NV access included):
//       CS = command << 24, INTERFACE0 = the data byte of a write
//   then DOIT; a read's answer comes back right justified in INTERFACE0.
//
// What the registers cannot carry is refused with link::UnsupportedCommand: 8-byte data
// (INTERFACE0 holds 32 bits), RPCs (their data length lives in the 8I20's table, not in
// the header), commands without an address (SSLBP sends the address from CS), data
// taken from a stored RPC (RID), 0xFF (it has no data byte) and headers 0x00..0x3F.
#pragma once

#include <cstdint>
#include <optional>

#include "lbp/command.hpp"

namespace i20::eth {

// What executing a step does to the 8I20, which decides where the link may put it in a
// packet of several DOITs (see passthrough_port.hpp).
enum class StepEffect {
  Read,          // data or local read: no side effect, harmless to repeat or to run early
  NvMode,        // 0xEC: changes what data addresses mean; the link tracks and restores it
  DataWrite,     // writes 8I20 memory (the EEPROM while NV access is on)
  LocalWrite,    // another repeatable local write (0xEA RPC memory access, addresses, ...)
  Unrepeatable,  // 0xFA adds to the address pointer, 0xFE resets: never run twice
};

struct PassthroughStep {
  std::uint32_t cs = 0;
  std::optional<std::uint32_t> interface0{};  // written before DOIT when set
  std::size_t reply_bytes = 0;                // taken from INTERFACE0 after DOIT
  // Executing the command twice leaves the 8I20 as executing it once: every command
  // except 0xFA (adds to the address pointer) and 0xFE (resets the processor).
  bool repeatable = true;
  bool data_write = false;                       // writes 8I20 memory (EEPROM when NV mode is on)
  std::optional<std::uint8_t> nv_access_mode{};  // set by 0xEC
  std::size_t wire_bytes = 0;  // serial bytes both ways, CRCs included: for timing estimates
  StepEffect effect = StepEffect::Read;
  std::size_t data_bytes = 0;  // of a data read or write (EEPROM write time scales with it)
};

// Throws link::UnsupportedCommand (completed = 0) naming the command and why.
PassthroughStep plan_passthrough(const lbp::Command& command);

// The reply data of a step from INTERFACE0: its low reply_bytes bytes, little endian.
lbp::Bytes reply_from_interface0(std::uint32_t interface0, std::size_t reply_bytes);

}  // namespace i20::eth
