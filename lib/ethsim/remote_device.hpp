// SPDX-License-Identifier: GPL-2.0-or-later
// What the virtual card's SSLBP talks to on each channel: an LBP device on the far end
// of an RS-422 line. The virtual card frames commands (CRC included) and parses the
// replies itself, exactly as the SSLBP firmware does; the device only moves bytes.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "lbp/bytes.hpp"
#include "lbp/command.hpp"

namespace i20::ethsim {

using Clock = std::chrono::steady_clock;

struct Exchange {
  lbp::Bytes reply;          // wire bytes received (data + CRC), maybe fewer than expected
  Clock::time_point done{};  // when the last reply byte was on the wire (or the wait ended)
};

class RemoteLbpDevice {
 public:
  virtual ~RemoteLbpDevice() = default;

  // Sends one framed command starting at `now` and collects up to `reply_wire_bytes`
  // bytes of reply, waiting at most `timeout` after the command has left.
  virtual Exchange exchange(lbp::ByteView framed_command, std::size_t reply_wire_bytes, Clock::time_point now,
                            Clock::duration timeout) = 0;

  // Time passes without traffic (watchdogs, EEPROM writes); stray output is dropped.
  virtual void advance(Clock::time_point now) = 0;

  // The device-specific setup SSLBP's normal start performs on this device (8I20 manual,
  // "8I20 DEVICE SPECIFIC SETUP": clear faults, QSETPOINT 0, loop on, 40 ms watchdog).
  virtual std::vector<lbp::Command> normal_start_commands() const { return {}; }
  // The normal start's commands went through: the device may now run what a normal start
  // sets up (the 8I20's watchdog).
  virtual void normal_started() {}

  // Short name for traces ("8I20 unit 0x00012345").
  virtual std::string describe() const = 0;
};

// The RPC SSLBP's normal mode runs every DOIT on an 8I20: 4 stream bytes (ANGLE,
// QSETPOINT) in, 8 bytes (TEMPERATURE, BUSV, STATUS, FAULT) out, in the order of the
// INTERFACE registers, LSW first (the simulator's pre-loaded table, sim/rpc_table.hpp).
inline constexpr unsigned kNormalCycleRpc = 3;
inline constexpr std::size_t kNormalCycleStreamBytes = 4;
inline constexpr std::size_t kNormalCycleReplyBytes = 8;

}  // namespace i20::ethsim
