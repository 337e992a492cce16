// SPDX-License-Identifier: GPL-2.0-or-later
// Profile against card: for every cell the profile writes, what the profile wants, what
// the card holds, and whether they are equal.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "params/param_db.hpp"
#include "profile/raw_values.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

struct DiffRow {
  std::string cell;   // e.g. "NVBRAKEONV"
  bool nv = false;    // an EEPROM cell: a change takes effect after reset
  std::string where;  // "file:line" of the entry asking for it
  std::int64_t profile_raw = 0;
  std::string profile_text;              // "190.00 V"
  std::optional<std::int64_t> card_raw;  // nullopt: not in the snapshot (unknown)
  std::string card_text;                 // "360.00 V", or "?" when unknown
  bool equal = false;
};

// One row per cell the profile writes, in profile order. Throws ProfileError if the
// profile writes a cell twice or a target cannot be met.
std::vector<DiffRow> diff(const Profile& profile, const params::ParamDb& db, const RawValues& card);

}  // namespace i20::profile
