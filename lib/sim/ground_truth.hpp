// SPDX-License-Identifier: GPL-2.0-or-later
// What a virtual 8I20 really holds, byte for byte, and which differences between two such
// snapshots nothing explains: the simulator's side of every "did the tool tell the truth"
// check (tests/ops, the fault soak). Judges by memory, never by what a tool reports.
#pragma once

#include <string>
#include <vector>

#include "lbp/bytes.hpp"
#include "lbp/local.hpp"
#include "sim/register_map.hpp"
#include "sim/virtual_8i20.hpp"

namespace i20::sim {

struct GroundTruth {
  lbp::Bytes ram;     // all 64 KiB
  lbp::Bytes eeprom;  // the EEPROM image
  lbp::local::NvAccess nv_access = lbp::local::NvAccess::Ram;
  bool rpcmem = false;
  bool powered = true;
  std::uint64_t resets = 0;  // processor resets so far (spontaneous, injected or asked for)
  // The host sent nothing after the last reset: no tool could have seen it (a reset right
  // after the reply to its last command is, to the host, a reset after the run).
  bool quiet_since_reset = false;
};

GroundTruth capture(const Virtual8i20& card);

// The raw value of a register in a snapshot.
std::uint64_t value_in(const GroundTruth& truth, const Register& reg);

// Whether working register `r` holds what a reset loads into it: its NV twin's value, or its
// power-up default when it has no twin.
bool reloaded_by_reset(const RegisterMap& map, const Register& r, const GroundTruth& after);

// Every byte that changed from `before` to `after` that nothing explains: not a cell in
// `named`, not a register the card changes itself (FAULT, STATUS, BUSV, TEMPERATURE,
// CLEARFAULT), and, when the card reset in between, not a working register reloaded from its
// NV twin (as the EEPROM held it before or after: a reset between the writes loads either)
// or its power-up default: a reload is the card's doing, never a write of the tool's. Empty:
// no stray write. Each entry names the byte.
std::vector<std::string> unexplained_changes(const RegisterMap& map, const GroundTruth& before,
                                             const GroundTruth& after, const std::vector<std::string>& named);

// Threshold pairs out of order in `truth` (BRAKEOFFV not below BRAKEONV, BUSUNDERV not below
// BUSOVERV), in the EEPROM and in the working set: "NVBRAKEOFFV 34000 >= NVBRAKEONV 19000".
std::vector<std::string> crossed_thresholds(const RegisterMap& map, const GroundTruth& truth);

}  // namespace i20::sim
