// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/backup.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string_view>
#include <tuple>

#include "files/atomic_file.hpp"
#include "lbp/bytes.hpp"
#include "profile/error.hpp"
#include "profile/loader.hpp"
#include "profile/timestamp.hpp"
#include "profile/writer.hpp"

namespace i20::profile {
namespace {

// Letters, digits, '-', '_' and '.' only, so a profile name cannot escape the directory.
std::string slug(const std::string& label) {
  std::string out;
  for (const char c : label) {
    const auto u = static_cast<unsigned char>(c);
    out += std::isalnum(u) || c == '-' || c == '_' || c == '.' ? c : '_';
  }
  while (!out.empty() && out.front() == '.') out.erase(out.begin());
  return out.empty() ? "profile" : out.substr(0, 64);
}

void check_reloads(const Profile& backup, const params::ParamDb& db, const std::filesystem::path& path) {
  try {
    const Profile again = load_profile_file(path, db);
    bool same = again.settings.size() == backup.settings.size();
    for (std::size_t i = 0; same && i < again.settings.size(); ++i)
      same = again.settings[i].name == backup.settings[i].name &&
             again.settings[i].raw == backup.settings[i].raw;
    if (!same) throw BackupError("backup " + path.string() + " does not read back to the values saved");
  } catch (const ProfileError& e) {
    throw BackupError("backup " + path.string() + " does not load back: " + e.what());
  }
}

}  // namespace

std::filesystem::path write_backup(const Profile& backup, const params::ParamDb& db,
                                   const std::filesystem::path& dir, const std::string& label,
                                   std::chrono::system_clock::time_point when) {
  const std::string text = to_yaml(backup, db);
  std::filesystem::path path;
  try {
    path = files::write_new_file(dir, "i20-backup-" + compact_utc(when) + "-" + slug(label), ".yaml", text);
  } catch (const OutputError& e) {
    throw BackupError(std::string("backup not written: ") + e.what());
  }
  try {
    check_reloads(backup, db, path);
  } catch (const BackupError&) {
    std::error_code ignored;
    std::filesystem::remove(path, ignored);  // a backup that does not restore is not left to be trusted
    throw;
  }
  return path;
}

namespace {

constexpr std::string_view kPrefix = "i20-backup-";
constexpr std::string_view kUnitTag = "-unit";

std::string unit_tag(std::uint32_t unit) {
  return std::string(kUnitTag) + lbp::hex_value(unit, 8).substr(2);
}

// "i20-backup-20261204-053407-<label>[-N].yaml": the time stamp (15 characters) and the
// suffix N (1 when none), which order backups of the same unit.
struct BackupName {
  std::string stamp;
  int suffix = 1;
};

std::optional<BackupName> parse_name(const std::string& name) {
  if (!name.starts_with(kPrefix) || !name.ends_with(".yaml")) return std::nullopt;
  BackupName parsed;
  parsed.stamp = name.substr(kPrefix.size(), 15);
  std::string stem = name.substr(0, name.size() - 5);
  const auto dash = stem.find_last_of('-');
  if (dash != std::string::npos && dash + 1 < stem.size() &&
      stem.find_first_not_of("0123456789", dash + 1) == std::string::npos && stem.size() - dash <= 4)
    parsed.suffix = std::stoi(stem.substr(dash + 1));
  return parsed;
}

}  // namespace

std::string backup_label(const std::string& profile_name, std::optional<std::uint32_t> unit) {
  return unit ? profile_name + unit_tag(*unit) : profile_name;
}

std::optional<std::uint32_t> unit_in_backup_name(const std::filesystem::path& file) {
  const std::string name = file.filename().string();
  if (!parse_name(name)) return std::nullopt;
  const auto at = name.rfind(kUnitTag);
  if (at == std::string::npos) return std::nullopt;
  const std::string digits = name.substr(at + kUnitTag.size(), 8);
  if (digits.size() != 8 || digits.find_first_not_of("0123456789ABCDEFabcdef") != std::string::npos)
    return std::nullopt;
  return static_cast<std::uint32_t>(std::stoul(digits, nullptr, 16));
}

std::vector<std::filesystem::path> backups_of_unit(const std::filesystem::path& dir, std::uint32_t unit,
                                                   std::string& problem) {
  struct Found {
    std::filesystem::path path;
    BackupName name;
    std::filesystem::file_time_type written;  // two backups in one second: the later one
  };
  std::vector<Found> found;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const auto name = parse_name(entry.path().filename().string());
    if (name && unit_in_backup_name(entry.path()) == unit) {
      std::error_code time_ec;
      found.push_back({entry.path(), *name, std::filesystem::last_write_time(entry.path(), time_ec)});
    }
  }
  if (ec) problem = ec.message();
  std::ranges::sort(found, [](const Found& a, const Found& b) {
    return std::tie(a.name.stamp, a.name.suffix, a.written) >
           std::tie(b.name.stamp, b.name.suffix, b.written);
  });
  std::vector<std::filesystem::path> paths;
  for (auto& f : found) paths.push_back(std::move(f.path));
  return paths;
}

std::filesystem::path default_backup_dir() {
  if (const char* state = std::getenv("XDG_STATE_HOME"); state && *state)
    return std::filesystem::path(state) / "i20" / "backups";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".local" / "state" / "i20" / "backups";
  return "i20-backups";
}

}  // namespace i20::profile
