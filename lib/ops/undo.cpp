// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/undo.hpp"

#include "device/errors.hpp"
#include "lbp/bytes.hpp"
#include "profile/backup.hpp"
#include "profile/error.hpp"
#include "profile/loader.hpp"

namespace i20::ops {

profile::AmpOrigin origin_of(const Amp& amp) {
  const auto& info = amp.identity().info;
  return profile::AmpOrigin{
      .unit_number = info.unit_number, .firmware = info.swrevision, .card = info.card_name};
}

BackupChoice backup_file(const std::filesystem::path& file, const params::ParamDb& db) {
  return BackupChoice{.file = file, .backup = profile::load_profile_file(file, db), .skipped = {}};
}

BackupChoice newest_valid_backup(const std::filesystem::path& dir, const Amp& amp) {
  const auto unit = amp.identity().info.unit_number;
  if (!unit) throw UsageError("the card did not report its unit number: name the backup file to restore");
  std::string problem;
  std::vector<std::string> skipped;
  for (const auto& file : profile::backups_of_unit(dir, *unit, problem)) {
    try {
      auto choice = backup_file(file, amp.db());
      choice.skipped = std::move(skipped);
      return choice;
    } catch (const profile::ProfileError& e) {
      skipped.push_back(file.string() + ": " + e.what());
    }
  }
  std::string message = "no backup of unit " + lbp::hex_value(*unit, 8) + " in " + dir.string();
  if (!problem.empty()) message += " (" + problem + ")";
  if (!skipped.empty())
    message += " that loads (passed over " + std::to_string(skipped.size()) + "; the newest, " +
               skipped.front() + ")";
  throw UsageError(message + ": name the backup file, or give --backup-dir");
}

std::vector<std::string> check_backup_origin(const BackupChoice& choice, const Amp& amp, bool force) {
  const auto& info = amp.identity().info;
  const auto& origin = choice.backup.origin;
  const auto unit = origin.unit_number ? origin.unit_number : profile::unit_in_backup_name(choice.file);
  const std::string here = info.unit_number ? "unit " + lbp::hex_value(*info.unit_number, 8) : "this card";
  std::vector<std::string> differences;
  if (!unit)
    differences.push_back(
        "it does not say which 8I20 it was read from (no origin: and no -unitNNNNNNNN in its name)");
  else if (*unit != info.unit_number)
    differences.push_back("it was read from unit " + lbp::hex_value(*unit, 8) + ", not " + here);
  if (origin.firmware && info.swrevision && *origin.firmware != *info.swrevision)
    differences.push_back("it was read from firmware (SWREVISION) " + std::to_string(*origin.firmware) +
                          ", this card runs " + std::to_string(*info.swrevision));
  if (!origin.card.empty() && !info.card_name.empty() && origin.card != info.card_name)
    differences.push_back("it was read from a " + origin.card + ", this card is a " + info.card_name);
  if (differences.empty() || force) return differences;
  std::string message = choice.file.string() + " is not a backup of " + here + ": ";
  for (std::size_t i = 0; i < differences.size(); ++i) message += (i ? "; " : "") + differences[i];
  throw device::SafetyError(
      message + ". Restoring it would put another amplifier's setup on this one; nothing was written",
      Advice::Force);
}

}  // namespace i20::ops
