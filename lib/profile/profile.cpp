// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/profile.hpp"

#include <set>

#include "profile/error.hpp"

namespace i20::profile {

bool MotorInfo::empty() const {
  return make.empty() && model.empty() && !continuous_current_a && !peak_current_a && !phase_resistance_ohm &&
         !line_to_line_resistance_ohm && !line_to_line_inductance_h && !poles &&
         !phase_inductance_h;
}

Memory Profile::target_of(const Setting& setting, const params::ParamDb& db) const {
  if (setting.target) return *setting.target;
  if (target) return *target;
  return db.get(setting.name).is_nv() ? Memory::Nv : Memory::Working;
}

std::string Profile::where(const Setting& setting) const {
  if (setting.line <= 0) return source;
  return source + ":" + std::to_string(setting.line);
}

std::vector<std::string> cells_of(const Profile& profile, const Setting& setting, const params::ParamDb& db) {
  const params::Param& p = db.get(setting.name);
  const Memory target = profile.target_of(setting, db);
  const auto need_twin = [&](const char* space) -> std::string {
    if (p.twin.empty())
      throw ProfileError(profile.where(setting), setting.name, "target",
                         std::string("target ") + to_string(target) + " needs the " + space + " twin of " +
                             p.name + ", and it has none");
    return p.twin;
  };
  switch (target) {
    case Memory::Nv: return {p.is_nv() ? p.name : need_twin("EEPROM")};
    case Memory::Working: return {p.is_nv() ? need_twin("working") : p.name};
    case Memory::Both: {
      const std::string twin = need_twin(p.is_nv() ? "working" : "EEPROM");
      return p.is_nv() ? std::vector<std::string>{p.name, twin} : std::vector<std::string>{twin, p.name};
    }
  }
  return {};
}

std::vector<CellWrite> cell_writes(const Profile& profile, const params::ParamDb& db) {
  std::vector<CellWrite> writes;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < profile.settings.size(); ++i) {
    const Setting& s = profile.settings[i];
    for (const auto& cell : cells_of(profile, s, db)) {
      if (!seen.insert(cell).second)
        throw ProfileError(profile.where(s), s.name, "duplicate",
                           cell +
                               " is already set by another entry (working and NV twins are one setting "
                               "when the target is both)");
      writes.push_back({cell, s.raw, i});
    }
  }
  return writes;
}

Profile retarget(Profile profile, Memory target, const params::ParamDb& db) {
  profile.target = target;
  for (auto& s : profile.settings) s.target.reset();
  (void)cell_writes(profile, db);  // throws if the new target makes two entries collide
  return profile;
}

}  // namespace i20::profile
