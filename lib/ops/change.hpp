// SPDX-License-Identifier: GPL-2.0-or-later
// The single-target writes (`i20 set A=1 B=2`, `wpd NAME VALUE`, `faults mask`) as small
// profiles for the one write transaction (lib/ops/apply_run.hpp checks them before any link opens).
#pragma once

#include <string>
#include <vector>

#include "device/amp.hpp"
#include "ops/core/amp.hpp"
#include "params/param_db.hpp"
#include "profile/profile.hpp"
#include "profile/save.hpp"

namespace i20::ops {

enum class ValueSyntax {
  Engineering,  // "320V", "7.5A", or a raw integer (i20 set)
  Raw,          // raw integers only, decimal or hex (wpd, like Mesa's WPD)
};

// "NAME=VALUE" strings (i20 set) into a profile whose entries target the space each name
// names. Throws UsageError / UnknownParameter / ValueError (bad input, nothing sent).
profile::Profile profile_from_assignments(const std::vector<std::string>& assignments,
                                          const params::ParamDb& db, ValueSyntax syntax);
// One name and value (wpd).
profile::Profile profile_from_value(const std::string& name, const std::string& value,
                                    const params::ParamDb& db, ValueSyntax syntax);

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
