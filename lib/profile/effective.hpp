// SPDX-License-Identifier: GPL-2.0-or-later
// What each cell of the card will hold once a profile is applied: the profile's value if
// it writes the cell, else the card's current value if known, else the database default.
// Cross-parameter rules judge these, so a profile that sets only NVBRAKEONV is checked
// against the NVBRAKEOFFV the card really has.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "params/param_db.hpp"
#include "profile/raw_values.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

enum class Origin { Profile, Card, Default };

struct Effective {
  const params::Param* param = nullptr;
  std::int64_t raw = 0;
  Origin origin = Origin::Default;
  const Setting* setting = nullptr;  // the entry that writes it, when origin is Profile

  double engineering() const { return static_cast<double>(raw) * param->scale; }
  // "NVBRAKEOFFV 345.00 V (profile)"
  std::string describe() const;
};

class EffectiveValues {
 public:
  // Throws ProfileError if the profile writes a cell twice or a target cannot be met.
  EffectiveValues(const Profile& profile, const params::ParamDb& db, const RawValues* card);

  // nullopt when the profile does not write it, the card's value is unknown and the
  // database has no default (e.g. NVMAXCURRENT: the manual gives no factory value).
  std::optional<Effective> get(const std::string& cell) const;
  // Does the profile write any cell in this space?
  bool touches(params::Space space) const;

 private:
  const Profile& profile_;
  const params::ParamDb& db_;
  const RawValues* card_;
  std::map<std::string, std::pair<std::int64_t, std::size_t>> written_;  // cell -> raw, setting
};

}  // namespace i20::profile
