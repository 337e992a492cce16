// SPDX-License-Identifier: GPL-2.0-or-later
// Shared helpers for the profile tests.
#pragma once

#include <algorithm>
#include <string>
#include <vector>

#include "params/param_db.hpp"
#include "profile/error.hpp"
#include "profile/finding.hpp"
#include "profile/loader.hpp"

namespace i20::profile::testing {

inline const params::ParamDb& db() {
  static const params::ParamDb instance = params::ParamDb::builtin();
  return instance;
}

inline Profile load(const std::string& yaml, const params::ParamDb& with = db()) {
  return load_profile_string(yaml, "test.yaml", with);
}

// A profile with just these parameter lines (each "NAME: value").
inline std::string with_params(const std::string& lines, const std::string& extra = "") {
  return "name: test\n" + extra + "parameters:\n" + lines;
}

// The ProfileError a YAML text raises, or a failure.
inline ProfileError load_error(const std::string& yaml) {
  try {
    load(yaml);
  } catch (const ProfileError& e) {
    return e;
  }
  throw std::runtime_error("expected a ProfileError for:\n" + yaml);
}

inline bool has_rule(const std::vector<Finding>& findings, const std::string& rule, Severity severity) {
  return std::ranges::any_of(findings,
                             [&](const Finding& f) { return f.rule == rule && f.severity == severity; });
}

inline bool has_rule(const std::vector<Finding>& findings, const std::string& rule) {
  return std::ranges::any_of(findings, [&](const Finding& f) { return f.rule == rule; });
}

inline std::string dump(const std::vector<Finding>& findings) {
  std::string out;
  for (const auto& f : findings)
    out += std::string(to_string(f.severity)) + " " + f.key + " [" + f.rule + "] " + f.message + " @" +
           f.where + "\n";
  return out;
}

}  // namespace i20::profile::testing
