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
#include "faults/report.hpp"
#include "ops/core/amp.hpp"
#include "ops/apply_run.hpp"
#include "ops/core/timing.hpp"

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
FaultReadings read_fault_registers(Amp& amp);

// A fault clear, judged by the rules that need no card when it is made: `i20 clear-faults`,
// `wpd FAULT 0` and the console's button make it before they open (or use) a link, so a
// refusal comes with nothing sent.
struct ClearJob {
  device::WriteOptions write;
  std::chrono::milliseconds wait;  // how long CLEARFAULT may stay set
};
// Throws SafetyError when CLEARFAULT's address is not confirmed and `write.allow_unverified`
// is not given.
ClearJob make_clear_job(const params::ParamDb& db, const device::WriteOptions& write,
                        std::chrono::milliseconds wait = timing::kClearFaultWait);

struct ClearResult {
  std::uint16_t fault_before = 0;
  FaultReadings after;
  std::chrono::milliseconds took{0};
  bool faults_remain() const { return after.fault != 0; }
  Outcome outcome() const { return faults_remain() ? Outcome::FaultsRemain : Outcome::Done; }
  // The bits the clear took away, and those still latched (masked ones marked).
  faults::Report cleared() const;
  faults::Report remaining() const;
};

// Sets CLEARFAULT, waits until the card acts on it (bounded by the job's wait), and reads
// the registers again. The card's own copy of the database judges the write again.
ClearResult clear_faults(Amp& amp, const ClearJob& job);

struct MaskResult {
  std::uint16_t before = 0;  // FAULTMASK as read
  std::uint16_t wanted = 0;
  TargetRun run;  // the transaction (nothing to do when already as asked)
};

// Masks (or unmasks) the maskable FAULT bit named by `key`, keeping every other bit as
// read. Throws faults::UnknownBit / NotMaskable (bad input / refused) before any write.
MaskResult set_fault_mask(Amp& amp, const std::string& key, bool masked, const device::WriteOptions& write);

}  // namespace i20::ops
