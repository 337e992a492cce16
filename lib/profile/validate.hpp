// Checks a profile against the parameter database and the manual's cross-parameter rules.
// Rule ids and their sources are listed in profiles/README.md.
#pragma once

#include <vector>

#include "params/param_db.hpp"
#include "profile/card_access.hpp"
#include "profile/finding.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

struct ValidationContext {
  // The card's current values. Rules that involve a cell the profile does not write use
  // the card's value when given here, else the database default.
  const RawValues* card = nullptr;
  // Guarded parameters (e.g. NVBAUDRATE) are an error unless forced, then a warning.
  bool force = false;
};

// All findings at once, in profile order then rule order. Never throws for a bad profile.
std::vector<Finding> validate(const Profile& profile, const params::ParamDb& db,
                              const ValidationContext& context = {});

}  // namespace i20::profile
