// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/save.hpp"

#include <set>

#include "profile/error.hpp"
#include "profile/timestamp.hpp"

namespace i20::profile {

std::vector<std::string> canonical_save_names(const std::vector<std::string>& names,
                                              const params::ParamDb& db) {
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const auto& name : names) {
    const params::Param& p = db.get(name);
    if (!p.writable())
      throw ProfileError("", p.name, "read-only",
                         "is read-only; a profile holds settings that can be written back");
    if (seen.insert(p.name).second) out.push_back(p.name);
  }
  return out;
}

std::vector<std::string> default_save_names(const params::ParamDb& db) {
  std::vector<std::string> names;
  for (const auto& p : db.all())
    if (p.is_nv() && p.writable() && p.guard.empty() && p.provenance.confirmed_on_all && p.address)
      names.push_back(p.name);
  return names;
}

std::vector<std::string> save_candidates(const params::ParamDb& db) {
  std::vector<std::string> names;
  for (const auto& p : db.all())
    if (p.is_nv() && p.writable() && p.provenance.confirmed_on_all && p.address) names.push_back(p.name);
  return names;
}

std::vector<std::string> names_to_save(const params::ParamDb& db, const RawValues& values) {
  std::vector<std::string> names;
  for (const auto& name : save_candidates(db)) {
    const params::Param& p = db.get(name);
    const auto it = values.find(name);
    if (it == values.end()) continue;
    if (p.guard.empty() || !p.default_value || *p.default_value != it->second) names.push_back(name);
  }
  return names;
}

Profile profile_from_values(const RawValues& values, const std::vector<std::string>& names,
                            const params::ParamDb& db, const std::string& card, const SaveOptions& options) {
  Profile profile;
  profile.source = "saved from " + card;
  profile.name = options.name;
  profile.notes = options.notes;
  profile.origin = options.origin;
  profile.comments = {"Read from " + card, "on " + iso8601_utc(options.when) + ".",
                      "Values are in engineering units; applying this file writes them back."};
  for (const auto& name : canonical_save_names(names, db)) {
    const auto it = values.find(name);
    if (it == values.end()) throw ProfileError("", name, "missing", "no value was read for it");
    profile.settings.push_back({name, it->second, std::nullopt, 0});
  }
  return profile;
}

}  // namespace i20::profile
