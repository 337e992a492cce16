// SPDX-License-Identifier: GPL-2.0-or-later
// Profiles back to YAML: what `save` and backups produce, in the schema the loader reads.
// Values are written in engineering units ("360.00 V") so a person can read and diff them;
// the text always loads back to exactly the same raw values.
#pragma once

#include <string>

#include "params/param_db.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

std::string to_yaml(const Profile& profile, const params::ParamDb& db);

}  // namespace i20::profile
