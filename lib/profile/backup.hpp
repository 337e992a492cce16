// SPDX-License-Identifier: GPL-2.0-or-later
// The backup an apply writes before it touches the card: a plain profile YAML of the
// values the card held, so anyone can diff it and re-apply it.
#pragma once

#include <chrono>
#include <filesystem>
#include <string>

#include "params/param_db.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

// Writes `backup` into `dir` (created if missing) as
// "i20-backup-<YYYYMMDD-HHMMSS>-<label>.yaml", never overwriting an existing file (a
// "-2", "-3", ... suffix is added), flushes it to disk, and loads it back to prove it
// re-applies to the same values. Returns the path. Throws BackupError on any failure.
std::filesystem::path write_backup(const Profile& backup, const params::ParamDb& db,
                                   const std::filesystem::path& dir, const std::string& label,
                                   std::chrono::system_clock::time_point when);

// Where backups go unless the user says otherwise: $XDG_STATE_HOME/i20/backups, else
// ~/.local/state/i20/backups (the XDG base directory rules), else ./i20-backups.
std::filesystem::path default_backup_dir();

}  // namespace i20::profile
