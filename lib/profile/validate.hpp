// SPDX-License-Identifier: GPL-2.0-or-later
// Checks a profile against the parameter database and the manual's cross-parameter rules.
// Rule ids and their sources are listed in profiles/README.md.
#pragma once

#include <optional>
#include <vector>

#include "params/param_db.hpp"
#include "profile/raw_values.hpp"
#include "profile/finding.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

struct ValidationContext {
  // The card's current values. Rules that involve a cell the profile does not write use
  // the card's value when given here, else the database default.
  const RawValues* card = nullptr;
  // Guarded parameters (e.g. NVBAUDRATE) are an error unless forced, then a warning; so
  // are thresholds at or below the measured bus voltage.
  bool force = false;
  // The bus voltage the card measures now (BUSV), when known: a BUSOVERV or BRAKEONV at or
  // below it faults the drive or loads the brake resistor at once.
  std::optional<double> measured_bus_v;
};

// Only the rules that need no card: read-only, guarded, range, and the card's fixed limits
// on each value alone (30 A, 385 V brake-on, baud index), which no database overlay can
// widen. Commands run it before they open the link, so a refused value sends nothing.
std::vector<Finding> validate_values(const Profile& profile, const params::ParamDb& db, bool force = false);

// All findings at once, in profile order then rule order. Never throws for a bad profile.
std::vector<Finding> validate(const Profile& profile, const params::ParamDb& db,
                              const ValidationContext& context = {});

}  // namespace i20::profile
