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
#include "ops/apply_run.hpp"
#include "ops/core/amp.hpp"
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

// A fault clear (`i20 clear-faults`, `wpd FAULT 0`, the console's button), judged by the
// rules that need no card when it is made, so a front end makes it before it opens (or
// uses) a link and a refusal comes with nothing sent: SafetyError when CLEARFAULT's address
// is not confirmed and `write.allow_unverified` is not given. run_on() sets CLEARFAULT,
// waits until the card acts on it (bounded by `wait`), and reads the registers again; the
// card's own copy of the database judges the write again.
class FaultClear {
 public:
  FaultClear(const params::ParamDb& db, const device::WriteOptions& write,
             std::chrono::milliseconds wait = timing::kClearFaultWait);
  ClearResult run_on(Amp& amp) const;

 private:
  device::WriteOptions write_;
  std::chrono::milliseconds wait_;  // how long CLEARFAULT may stay set
};

struct MaskResult {
  std::uint16_t before = 0;  // FAULTMASK as read
  std::uint16_t wanted = 0;
  TargetRun run;                       // the transaction (nothing to do when already as asked)
  std::optional<FaultReadings> after;  // the registers once the change ended well
};

// Masks (or unmasks) the maskable FAULT bit named by `key` (`i20 faults mask`), keeping every
// other bit as read. Made before the link opens: an unknown or unmaskable bit
// (faults::UnknownBit / NotMaskable) and what the rules already know of FAULTMASK (address,
// range) are refused with nothing sent. run_on() reads FAULTMASK, writes it through the one
// write transaction (ValueChange) and reads the fault registers again.
class FaultMaskChange {
 public:
  FaultMaskChange(const params::ParamDb& db, std::string key, bool masked, const device::WriteOptions& write);
  MaskResult run_on(Amp& amp) const;

 private:
  std::string key_;
  bool masked_;
  device::WriteOptions write_;
};

}  // namespace i20::ops
