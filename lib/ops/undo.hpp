// SPDX-License-Identifier: GPL-2.0-or-later
// `profile undo`: which backup to restore, and whether it belongs on this card. The restore
// itself is apply's transaction (run_apply_on), so it is validated, planned, backed up,
// verified and rolled back like any apply.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "ops/core/amp.hpp"
#include "profile/profile.hpp"

namespace i20::ops {

// The 8I20 behind `card` as a profile's `origin:` records it.
profile::AmpOrigin origin_of(const Amp& amp);

struct BackupChoice {
  std::filesystem::path file;
  profile::Profile backup;
  // Newer backups of the unit passed over, each "FILE: why" (a 0-byte file a full disk left,
  // one that does not load): said to the user, never silently skipped.
  std::vector<std::string> skipped;
};

// The newest backup of the card's unit in `dir` that loads as a profile. Throws UsageError
// when there is none (naming the folder, and what was passed over).
BackupChoice newest_valid_backup(const std::filesystem::path& dir, const Amp& amp);

// Loads a named backup file (ProfileError on a bad one).
BackupChoice backup_file(const std::filesystem::path& file, const params::ParamDb& db);

// A backup restores the card it was read from. Throws SafetyError (exit 3, Advice::Force)
// when its origin (the `origin:` block, else the unit in its file name) names another unit,
// other firmware or another card, or when it names no unit at all; `force` lets it through.
// Returns the differences that `force` let through (empty when there were none), for the
// report.
std::vector<std::string> check_backup_origin(const BackupChoice& choice, const Amp& amp, bool force);

}  // namespace i20::ops
