// SPDX-License-Identifier: GPL-2.0-or-later
// Reading a card into a profile: `save` for people, and the backup taken before an apply.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "params/param_db.hpp"
#include "profile/profile.hpp"
#include "profile/raw_values.hpp"

namespace i20::profile {

struct SaveOptions {
  std::string name = "saved";  // the profile's name
  std::string notes;
  std::chrono::system_clock::time_point when = std::chrono::system_clock::now();
  AmpOrigin origin;  // the card read: written as `origin:` so an undo can check it is this card
};

// What `save` reads when no names are given: the writable EEPROM parameters whose
// addresses are public for every firmware (docs/facts.md s2) and that need no --force, i.e.
// the power-up setup of the drive.
std::vector<std::string> default_save_names(const params::ParamDb& db);

// What `save` (and the report's parameters section) read when no names are given: the
// default names and the guarded writable EEPROM parameters (NVBAUDRATE) whose addresses are
// public for every firmware.
std::vector<std::string> save_candidates(const params::ParamDb& db);
// Of the candidates in `values`, those a saved profile holds: every default name, and each
// guarded one whose value differs from its database default, so that a spare card restored
// from the file comes back the same (at the same baud rate). Applying a guarded value
// needs --force; the writer says so in a comment.
std::vector<std::string> names_to_save(const params::ParamDb& db, const RawValues& values);

// Database spelling, read-only names refused (ProfileError), duplicates dropped, order kept.
std::vector<std::string> canonical_save_names(const std::vector<std::string>& names,
                                              const params::ParamDb& db);

// A profile holding `values` for `names` (each in its own space: NV names -> nv), with
// provenance comments naming `card` and the time. Throws ProfileError for a read-only or
// missing name, UnknownParameter for a name not in the database.
Profile profile_from_values(const RawValues& values, const std::vector<std::string>& names,
                            const params::ParamDb& db, const std::string& card, const SaveOptions& options);

}  // namespace i20::profile
