// SPDX-License-Identifier: GPL-2.0-or-later
// The single-target writes (`i20 set A=1 B=2`, `wpd NAME VALUE`, the console's change,
// `faults mask`): one use case, ValueChange, that makes a small profile for the one write
// transaction (lib/ops/apply_run.hpp) and judges it before any link opens.
#pragma once

#include <string>
#include <vector>

#include "device/amp.hpp"
#include "ops/apply_run.hpp"
#include "ops/core/amp.hpp"
#include "ops/profile_apply.hpp"
#include "params/param_db.hpp"
#include "profile/profile.hpp"
#include "profile/save.hpp"

namespace i20::ops {

enum class ValueSyntax {
  Engineering,  // "320V", "7.5A", or a raw integer (i20 set)
  Raw,          // raw integers only, decimal or hex (wpd, like Mesa's WPD)
};

// A name and the value the user wrote for it, as given.
struct NamedValue {
  std::string name;
  std::string value;
};

// "NAME=VALUE" words (i20 set, the console) as names and values. Throws UsageError for a
// word that is not one.
std::vector<NamedValue> named_values(const std::vector<std::string>& assignments);

// What the user asked to write to one card, in the words of the front end.
struct ValueChangeRequest {
  std::vector<NamedValue> values;  // in the user's order
  ValueSyntax syntax = ValueSyntax::Engineering;
  bool force = false;             // the one --force (apply_run.hpp, ApplyRequest)
  bool allow_unverified = false;  // write working addresses the database does not confirm
  bool dry_run = false;           // read, validate and plan; write nothing
  Cancel cancel{};                // Ctrl-C
};

// The use case: the values as a profile whose entries target the space each name names,
// applied as a profile is (ProfileApply): judged by every rule that needs no card when it is made, so a front
// end makes it before it opens a link and a refusal comes with nothing sent. Throws UsageError /
// UnknownParameter / ValueError (bad input) or SafetyError (a rule). run_on() runs the one write transaction
// on the opened card: the same job a dry run plans.
class ValueChange {
 public:
  ValueChange(const ValueChangeRequest& request, const params::ParamDb& db);
  ValueChange(const ValueChange&) = delete;  // the apply's job points at the profile held here
  ValueChange& operator=(const ValueChange&) = delete;

  const profile::Profile& profile() const { return profile_; }
  TargetRun run_on(Amp& amp, const Activity& activity = {}) const;

 private:
  profile::Profile profile_;
  ProfileApply apply_;
};

// Reads `names` (if empty: profile::save_candidates(), keeping profile::names_to_save()) into a profile
// (`profile save`, `report`). Every value must be a fact on this card: a name whose address
// is not confirmed for its firmware is refused (SafetyError), not saved as a guess.
profile::Profile save_profile(Amp& amp, const std::vector<std::string>& names,
                              const profile::SaveOptions& options);

// Refused before the link opens: a name that is read-only (a saved profile holds settings
// that can be written back). Throws UsageError.
void check_save_names(const std::vector<std::string>& names, const params::ParamDb& db);

// A saved card: the profile and its YAML, proved to load back to exactly the values read
// before anyone relies on it (Error otherwise). `source` names the file in messages.
struct SavedAmp {
  profile::Profile profile;
  std::string yaml;
};
SavedAmp save_card(Amp& amp, const std::vector<std::string>& names, const profile::SaveOptions& options,
                   const std::string& source);

}  // namespace i20::ops
