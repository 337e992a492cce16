// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/backup.hpp"

#include <cstdlib>

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "profile/error.hpp"
#include "profile/loader.hpp"
#include "profile/timestamp.hpp"
#include "profile/writer.hpp"

namespace i20::profile {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

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

// Opens a file that did not exist before ("x": O_EXCL), trying numbered names on a clash.
std::pair<File, std::filesystem::path> create_unique(const std::filesystem::path& dir,
                                                     const std::string& stem) {
  for (int n = 1; n < 1000; ++n) {
    std::string name = stem;  // appended apart: GCC 12's -O3 -Wrestrict misfires on `"-" + std::to_string(n)`
    if (n > 1) {
      name += '-';
      name += std::to_string(n);
    }
    const auto path = dir / (name + ".yaml");
    File f(std::fopen(path.c_str(), "wx"));
    if (f) return {std::move(f), path};
    if (errno != EEXIST)
      throw BackupError("cannot create backup " + path.string() + ": " + std::strerror(errno));
  }
  throw BackupError("cannot find a free backup name in " + dir.string());
}

void write_all(std::FILE* f, const std::string& text, const std::filesystem::path& path) {
  if (std::fwrite(text.data(), 1, text.size(), f) != text.size() || std::fflush(f) != 0 ||
      ::fsync(fileno(f)) != 0)
    throw BackupError("cannot write backup " + path.string() + ": " + std::strerror(errno));
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
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw BackupError("cannot create backup directory " + dir.string() + ": " + ec.message());
  const std::string text = to_yaml(backup, db);
  auto [file, path] = create_unique(dir, "i20-backup-" + compact_utc(when) + "-" + slug(label));
  write_all(file.get(), text, path);
  if (std::fclose(file.release()) != 0)
    throw BackupError("cannot close backup " + path.string() + ": " + std::strerror(errno));
  check_reloads(backup, db, path);
  return path;
}

std::filesystem::path default_backup_dir() {
  if (const char* state = std::getenv("XDG_STATE_HOME"); state && *state)
    return std::filesystem::path(state) / "i20" / "backups";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".local" / "state" / "i20" / "backups";
  return "i20-backups";
}

}  // namespace i20::profile
