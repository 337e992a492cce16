// SPDX-License-Identifier: GPL-2.0-or-later
// One profile applied to one card, from opening the link to the final state: what `i20
// profile apply`, every fleet target, `i20 set`, `wpd` and `faults mask` run.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "device/amp.hpp"
#include "ops/core/amp.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/outcome.hpp"
#include "ops/core/transaction.hpp"
#include "params/param_db.hpp"
#include "profile/profile.hpp"

namespace i20::ops {

using Activity = std::function<void(const std::string&)>;
// Opens one card (a fleet target over its own line or a shared Ethernet port); throws.
using AmpOpener = std::function<std::unique_ptr<Amp>()>;

// What the user asked for, in the words of the command line: every command that changes a
// card (`i20 set`, `wpd`, `profile apply`/`undo`, a fleet, validate's dry run) says it here,
// and make_apply_job() turns it into the job, so one user flag is one setting everywhere.
struct ApplyRequest {
  const profile::Profile* profile = nullptr;
  const params::ParamDb* db = nullptr;  // as loaded: each card resolves its own map from it
  // The one --force: the device layer's guards (NVBAUDRATE, setpoints) and the validation
  // rules it overrides (the measured-bus thresholds, unstable loops).
  bool force = false;
  bool allow_unverified = false;                      // write working addresses the database does not confirm
  bool dry_run = false;                               // read, validate and plan; write nothing
  bool reset = false;                                 // reset the card once the EEPROM writes are verified
  std::optional<std::filesystem::path> backup_dir{};  // none: no backup (i20 set, wpd)
  Cancel cancel{};                                    // Ctrl-C
  OpenOptions open{};                                 // how links are opened (run_apply, fleets)
  std::function<void(const profile::Plan&)> on_plan{};  // told the plan before the first write

  // The device layer's share of the request (also what make_apply_job() judges).
  device::WriteOptions write_options() const { return {allow_unverified, force}; }
};

struct ApplyJob {
  const profile::Profile* profile = nullptr;
  const params::ParamDb* db = nullptr;  // as loaded: each card resolves its own map from it
  TransactionOptions transaction;       // dry run, reset, backup directory, Ctrl-C (its force: below)
  device::WriteOptions write;           // force, allow_unverified: the one force of the job
  OpenOptions open;                     // how links are opened
};

// The job for a request: the only place a job's settings are assembled, and the only way to
// a job. Every rule that needs no card is judged here, for every cell of the profile
// (read-only, known address, range, guard, the card's fixed limits): a front end makes the
// job before it opens a link, so a refusal (SafetyError, exit 3, naming the first broken
// rule) comes with nothing sent. The cross-parameter rules compare with the card's own
// values and its measured bus, so the transaction judges them, before its first write.
ApplyJob make_apply_job(const ApplyRequest& request);

struct TargetRun {
  Endpoint target;
  std::optional<TransactionResult> result;  // nullopt: the card was never reached
  std::string error;                        // why it was not reached
  Advice error_advice = Advice::None;       // what overrides `error`, for the app to name
  Outcome outcome = Outcome::Failed;
  // NV cells whose working twin differs from the EEPROM after the run: values that are
  // not live until the next reset (also after a "nothing to do" run, when an earlier
  // write was never followed by a reset). Only where the working twin is confirmed.
  std::vector<std::string> not_live;
  // The card reset itself while the profile was being applied (STATUS sticky bits), so
  // its working values were reloaded from the EEPROM as it was at that moment.
  std::string card_reset;
  // The line failed with NV access or RPC memory mode on and the card did not confirm it
  // left: why, and the way back (the outcome is then Uncertain).
  std::string mode_left_on;
  bool refused_by_card = false;  // the device layer's safety rules refused a planned write
  std::size_t retries = 0;       // reads/writes repeated after lost or garbled replies
  double seconds = 0;

  int exit_code() const { return ops::exit_code(outcome); }
  bool ok() const { return exit_code() == kExitOk; }
};

// Opens the target, runs the transaction, closes it. Never throws: every failure ends in
// the run's outcome, result or error.
TargetRun run_apply(const Endpoint& target, const ApplyJob& job, const Activity& activity = {});
// The same over a link the caller opened (the fleet's shared Ethernet ports).
TargetRun run_apply_over(std::unique_ptr<link::Link> link, const Endpoint& target, const ApplyJob& job,
                         const Activity& activity = {});
// The same on the card `open` opens (the fleet's scheduling, lib/ops/fleet.hpp).
TargetRun run_apply_opened(const Endpoint& target, const ApplyJob& job, const AmpOpener& open,
                           const Activity& activity = {});
// The same on a card that is already open (the single-target commands).
TargetRun run_apply_on(Amp& amp, const ApplyJob& job, const Activity& activity = {});

// The fleet's outcome: Done only if every run ended well, else the most serious one.
Outcome fleet_outcome(const std::vector<TargetRun>& runs);

}  // namespace i20::ops
