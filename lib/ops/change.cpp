// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/change.hpp"

#include "device/errors.hpp"
#include "ops/core/read.hpp"
#include "ops/undo.hpp"
#include "params/value.hpp"
#include "profile/loader.hpp"
#include "profile/writer.hpp"

namespace i20::ops {
namespace {

constexpr const char* kCommandLine = "command line";

profile::Setting setting(const params::Param& p, const std::string& text, ValueSyntax syntax, int position) {
  profile::Setting s;
  s.name = p.name;
  s.raw = syntax == ValueSyntax::Raw ? params::parse_raw(p, text) : params::parse_value(p, text);
  s.line = position;
  return s;
}

profile::Profile small_profile() {
  profile::Profile profile;
  profile.source = kCommandLine;
  profile.name = "command-line";
  return profile;
}

profile::Profile change_profile(const std::vector<NamedValue>& values, const params::ParamDb& db,
                                ValueSyntax syntax) {
  auto profile = small_profile();
  int position = 0;
  for (const auto& v : values) {
    ++position;
    const auto& p = db.get(v.name);
    for (const auto& earlier : profile.settings)
      if (earlier.name == p.name) throw UsageError(p.name + " is given twice on the command line");
    profile.settings.push_back(setting(p, v.value, syntax, position));
  }
  if (profile.settings.empty()) throw UsageError("nothing to write: give NAME=VALUE pairs");
  return profile;
}

}  // namespace

std::vector<NamedValue> named_values(const std::vector<std::string>& assignments) {
  std::vector<NamedValue> values;
  for (const auto& a : assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == a.size())
      throw UsageError("'" + a + "' is not NAME=VALUE (e.g. NVBRAKEONV=320V or NVMAXCURRENT=raw:750)");
    values.push_back({a.substr(0, eq), a.substr(eq + 1)});
  }
  return values;
}

ValueChange::ValueChange(const ValueChangeRequest& request, const params::ParamDb& db)
    : profile_(change_profile(request.values, db, request.syntax)),
      apply_({.profile = &profile_,
              .db = &db,
              .force = request.force,
              .allow_unverified = request.allow_unverified,
              .dry_run = request.dry_run,
              .cancel = request.cancel}) {}

TargetRun ValueChange::run_on(Amp& amp, const Activity& activity) const {
  return apply_.run_on(amp, activity);
}

profile::Profile save_profile(Amp& amp, const std::vector<std::string>& names,
                              const profile::SaveOptions& options) {
  const auto wanted =
      profile::canonical_save_names(names.empty() ? profile::save_candidates(amp.db()) : names, amp.db());
  profile::RawValues values;
  for (const auto& r : read_values(amp, wanted)) {
    if (!r.fact())
      throw device::SafetyError(r.param->name + " is " + unknown_text(r) + " on " + amp.describe() +
                                ": not saved as a guess");
    values[r.param->name] = *r.raw;
  }
  // Named ones are saved as asked; by default every NV value a restore needs (guarded ones
  // that differ from the default included).
  const auto saved = names.empty() ? profile::names_to_save(amp.db(), values) : wanted;
  auto with_origin = options;
  with_origin.origin = origin_of(amp);
  return profile::profile_from_values(values, saved, amp.db(), amp.describe(), with_origin);
}

void check_save_names(const std::vector<std::string>& names, const params::ParamDb& db) {
  for (const auto& n : names)
    if (!db.get(n).writable())
      throw UsageError(n + " is read-only: a profile holds settings that can be written back");
}

SavedAmp save_card(Amp& amp, const std::vector<std::string>& names, const profile::SaveOptions& options,
                   const std::string& source) {
  SavedAmp saved{save_profile(amp, names, options), {}};
  saved.yaml = profile::to_yaml(saved.profile, amp.db());
  const auto again = profile::load_profile_string(saved.yaml, source, amp.db());
  for (std::size_t i = 0; i < saved.profile.settings.size(); ++i)
    if (again.settings.at(i).raw != saved.profile.settings[i].raw)
      throw Error("the saved profile does not read back to the values read from the card");
  return saved;
}

}  // namespace i20::ops
