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
  // The bus voltage the card measures now (BUSV), when known: every threshold the profile
  // writes is judged against it (measured_bus_findings below).
  std::optional<double> measured_bus_v;
};

// Only the rules that need no card: read-only, guarded, range, and the card's fixed limits
// on each value alone (30 A, 385 V brake-on, baud index), which no database overlay can
// widen. Commands run it before they open the link, so a refused value sends nothing.
std::vector<Finding> validate_values(const Profile& profile, const params::ParamDb& db, bool force = false);

// All findings at once, in profile order then rule order. Never throws for a bad profile.
// To judge values already on a card (e.g. the pending NV values before a reset makes them
// live), pass them as a profile and the card's other values as context.card.
std::vector<Finding> validate(const Profile& profile, const params::ParamDb& db,
                              const ValidationContext& context = {});

// The voltage thresholds against the bus the card measures now, each cell on its own: what
// `set`, `profile apply` and `reset` refuse unless forced. `cells` maps database names to
// raw values (working or NV cells; names that are not thresholds are ignored). For each:
//   BUSOVERV at or below the bus      bus-measured-overvoltage    the drive faults
//   BRAKEONV at or below the bus      bus-measured-brake          the brake resistor takes the supply's power
//   BRAKEOFFV at or below the bus     bus-measured-brake-off      once on, the brake never switches off
//   BUSUNDERV at or above the bus     bus-measured-undervoltage   the drive faults (bus under-voltage)
//   BUSUNDERVMAX at or above the bus  bus-measured-undervoltage-max  an under-voltage fault never clears
// A working cell acts at once, an NV cell from the next reset; the message says which.
// Errors, or warnings when `force`. Findings carry the cell as key and no `where`.
std::vector<Finding> measured_bus_findings(const RawValues& cells, double measured_bus_v,
                                           const params::ParamDb& db, bool force);

}  // namespace i20::profile
