// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 inventory`: what every amplifier of a fleet is, read-only, one row per target:
// identity, firmware and whether its map is confirmed, FAULT/STATUS, and (given a profile)
// whether it holds the profile, by the same comparison `profile diff` makes.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "ops/core/amp.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/faults.hpp"
#include "ops/core/outcome.hpp"
#include "profile/diff.hpp"
#include "profile/profile.hpp"

namespace i20::ops {

struct InventoryJob {
  const params::ParamDb* db = nullptr;        // as loaded: each card resolves its own map
  const profile::Profile* profile = nullptr;  // nullptr: no comparison
  OpenOptions open;
  Cancel cancel;
};

struct InventoryRow {
  Endpoint target;
  std::optional<Identity> identity;  // nullopt: the card was not reached (see error)
  std::string card;                  // Amp::describe()
  std::string error;                 // why it was not reached, or why the read stopped
  Outcome outcome = Outcome::Failed;
  std::optional<FaultReadings> faults;
  std::string faults_error;  // why FAULT/STATUS are unknown
  // The profile against the card, as `profile diff` reports it (empty without a profile).
  std::vector<profile::DiffRow> diff;
  // The hostmot2 name of an 8I20 on an SSERIAL channel ("8i20.PORT.CHANNEL" under the
  // board's hm2 prefix); empty for a serial or simulated card.
  std::string linuxcnc_name;

  bool reached() const { return identity.has_value(); }
  bool outcome_ok() const;  // read to the end
  // Whether the card holds every value of the profile: nullopt when it was not read, or when
  // a cell's value is unknown (its address is not confirmed for the card's firmware).
  std::optional<bool> matches() const;
};

// Every row equal: true; a cell unknown: nullopt; else false.
std::optional<bool> profile_matches(const std::vector<profile::DiffRow>& rows);

// Cells of `profile` against what `card` holds, read honestly (an unconfirmed address is
// unknown): the comparison `i20 profile diff` prints.
std::vector<profile::DiffRow> diff_card(Amp& amp, const profile::Profile& profile);

// Reads every target, concurrently across lines (targets sharing a serial line, a simulator
// image or an Ethernet card are read one after another). One row per target, in order. Never
// throws for a card: each failure ends in its row.
std::vector<InventoryRow> read_inventory(const std::vector<Endpoint>& targets, const InventoryJob& job);

// Of all rows, the outcome that needs attention first (Done when every card was read).
Outcome inventory_outcome(const std::vector<InventoryRow>& rows);

}  // namespace i20::ops
