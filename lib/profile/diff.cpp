// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/diff.hpp"

#include "params/value.hpp"

namespace i20::profile {

std::vector<DiffRow> diff(const Profile& profile, const params::ParamDb& db, const RawValues& card) {
  std::vector<DiffRow> rows;
  for (const auto& w : cell_writes(profile, db)) {
    const params::Param& p = db.get(w.cell);
    DiffRow row;
    row.cell = p.name;
    row.nv = p.is_nv();
    row.where = profile.where(profile.settings[w.setting]);
    row.profile_raw = w.raw;
    row.profile_text = params::format_engineering(p, w.raw);
    if (const auto it = card.find(p.name); it != card.end()) {
      row.card_raw = it->second;
      row.card_text = params::format_engineering(p, it->second);
      row.equal = it->second == w.raw;
    } else {
      row.card_text = std::string(1, '?');  // not = "?": GCC 12 -Wrestrict false positive
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace i20::profile
