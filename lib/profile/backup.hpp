// SPDX-License-Identifier: GPL-2.0-or-later
// The backup an apply writes before it touches the card: a plain profile YAML of the
// values the card held, so anyone can diff it and re-apply it.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

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

// The label part of a backup's name: "<profile name>-unit00012345" (the unit's 8 hex digits),
// or the profile name alone when the unit is not known.
std::string backup_label(const std::string& profile_name, std::optional<std::uint32_t> unit);
// The unit a backup's file name carries ("...-unit00012345.yaml", or "-unit00012345-2.yaml"),
// if any: backups written before `origin:` existed say it only there.
std::optional<std::uint32_t> unit_in_backup_name(const std::filesystem::path& file);
// The backups of `unit` in `dir` written by write_backup(), newest first (by the UTC time
// stamp in the name, then the "-2", "-3" suffix for the same second). Empty when the folder
// does not exist; `problem` says why a folder could not be listed.
std::vector<std::filesystem::path> backups_of_unit(const std::filesystem::path& dir, std::uint32_t unit,
                                                   std::string& problem);

// Where backups go unless the user says otherwise: $XDG_STATE_HOME/i20/backups, else
// ~/.local/state/i20/backups (the XDG base directory rules), else ./i20-backups.
std::filesystem::path default_backup_dir();

}  // namespace i20::profile
