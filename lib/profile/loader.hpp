// SPDX-License-Identifier: GPL-2.0-or-later
// Strict profile loader: a bad profile is refused with "file:line: key: reason [rule]"
// before anything talks to a card. The schema is described in profiles/README.md.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "params/param_db.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

// Throws ProfileError naming the file, line, key and rule. Checks the shape of the file,
// the parameter names (with suggestions), units and value syntax, and targets; ranges and
// cross-parameter rules are validate()'s job, so that they can be reported all at once.
Profile load_profile_string(std::string_view yaml, const std::string& source, const params::ParamDb& db);
Profile load_profile_file(const std::filesystem::path& path, const params::ParamDb& db);

}  // namespace i20::profile
