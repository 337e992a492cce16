// One profile applied to one card, from opening the link to the final state: what both
// `i20 profile apply` and the fleet run for each target.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "amp_card_access.hpp"
#include "params/param_db.hpp"
#include "profile/apply.hpp"
#include "profile/profile.hpp"
#include "target_spec.hpp"

namespace i20::cli {

struct ApplyJob {
  const profile::Profile* profile = nullptr;
  const params::ParamDb* db = nullptr;  // copied per target: identify() selects the firmware in it
  profile::ApplyOptions apply;
  CardAccessOptions card;
};

struct TargetRun {
  std::string target;                          // as the user named it
  std::string target_flags;                    // "--port /dev/ttyUSB0", for advice lines
  std::optional<profile::ApplyResult> result;  // nullopt: the card was never reached
  std::string error;                           // why it was not reached
  // NV cells whose working twin differs from the EEPROM after the run: values that are
  // not live until the next reset (also after a "nothing to do" run, when an earlier
  // apply was never followed by a reset). Only where the working map is confirmed.
  std::vector<std::string> not_live;
  // The card reset itself while the profile was being applied (STATUS sticky bits), so
  // its working values were reloaded from the EEPROM as it was at that moment.
  std::string card_reset;
  bool refused_by_card = false;  // the device layer's safety rules refused a planned write
  bool interrupted = false;      // Ctrl-C
  std::size_t retries = 0;       // reads/writes repeated after lost or garbled replies
  double seconds = 0;
  int exit_code = 0;
};

using Activity = AmpCardAccess::Activity;

// Never throws: every failure ends in the run's result or error.
TargetRun run_apply(const TargetSpec& target, const ApplyJob& job, const Activity& activity = {});

// The exit code of one run: 0 applied and verified / nothing to do / dry run, 2 invalid
// profile, 3 refused by a safety rule, 4 rolled back (or rollback failed, or the reset
// after a verified apply failed), 1 link failure before anything was written, 130 Ctrl-C.
int exit_code_of(const TargetRun& run);

// The fleet's: 0 only if every run is 0, else the most serious code among them
// (4, then 130, 1, 3, 2): a card left needing attention outranks one never touched.
int fleet_exit_code(const std::vector<TargetRun>& runs);

// Applied and verified, nothing to do, or a dry run: the card is as the profile asks
// (or, for a dry run, untouched on request).
bool run_ok(const TargetRun& run);

}  // namespace i20::cli
