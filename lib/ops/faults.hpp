// SPDX-License-Identifier: GPL-2.0-or-later
// The fault use cases: read the registers that explain a fault (honestly: FAULT and STATUS
// only from confirmed addresses), clear faults through CLEARFAULT, and mask the one
// maskable fault through the write transaction.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "device/amp.hpp"
#include "ops/amp.hpp"
#include "ops/apply_run.hpp"

namespace i20::ops {

// One pass over the registers that explain a fault. Optional members are empty when their
// address is not confirmed for the card's firmware (unknown, not guessed).
struct FaultReadings {
  std::uint16_t fault = 0;
  std::uint16_t status = 0;
  std::optional<std::uint16_t> faultmask;
  std::optional<double> busv_v;
  std::optional<double> temperature_c;
  std::optional<double> busunderv_v;
  std::optional<double> busoverv_v;
  std::optional<double> brakeonv_v;  // the working threshold the brake compares the bus with
  // Cells asked for but not read as facts (address not confirmed for this firmware, or no
  // answer): their fields above stay empty, and a claim about them says so.
  std::vector<std::string> not_confirmed;
};

// FAULT and STATUS are required: throws SafetyError (nothing read, exit 3) when their
// addresses are not confirmed for this card, since a guessed address would report "no
// faults" from some other register. The rest are read where confirmed.
FaultReadings read_fault_registers(Amp& card);

struct ClearResult {
  std::uint16_t fault_before = 0;
  FaultReadings after;
  std::chrono::milliseconds took{0};
  bool faults_remain() const { return after.fault != 0; }
  Outcome outcome() const { return faults_remain() ? Outcome::FaultsRemain : Outcome::Done; }
};

// Sets CLEARFAULT, waits until the card acts on it (bounded by `wait`), and reads the
// registers again. Refused (before anything is sent) when CLEARFAULT's address is not
// confirmed and `write.allow_unverified` is not given.
ClearResult clear_faults(Amp& card, const device::WriteOptions& write, std::chrono::milliseconds wait);

struct MaskResult {
  std::uint16_t before = 0;  // FAULTMASK as read
  std::uint16_t wanted = 0;
  TargetRun run;  // the transaction (nothing to do when already as asked)
};

// Masks (or unmasks) the maskable FAULT bit named by `key`, keeping every other bit as
// read. Throws faults::UnknownBit / NotMaskable (bad input / refused) before any write.
MaskResult set_fault_mask(Amp& card, const std::string& key, bool masked, const device::WriteOptions& write);

}  // namespace i20::ops
