// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile_lookup.hpp"

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include "version/build_info.hpp"

namespace i20::cli {
namespace {

namespace fs = std::filesystem;

void add_unique(std::vector<profile::SearchDir>& dirs, const fs::path& dir, const std::string& origin) {
  if (dir.empty()) return;
  const fs::path normal = dir.lexically_normal();
  for (const auto& d : dirs)
    if (d.dir == normal) return;
  dirs.push_back({normal, origin});
}

void add_environment(std::vector<profile::SearchDir>& dirs) {
  const char* value = std::getenv("I20_PROFILE_PATH");
  if (!value) return;
  const std::string list = value;
  for (std::size_t begin = 0; begin <= list.size();) {
    const std::size_t end = std::min(list.find(':', begin), list.size());
    add_unique(dirs, list.substr(begin, end - begin), "$I20_PROFILE_PATH");
    begin = end + 1;
  }
}

}  // namespace

fs::path own_executable() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe;
}

std::vector<profile::SearchDir> profile_search_dirs() {
  std::vector<profile::SearchDir> dirs;
  add_environment(dirs);
  const fs::path exe = own_executable();
  // PREFIX/bin/i20 -> PREFIX/share/i20tools/profiles: right after the tree was moved too
  // (a staging root, DESTDIR), which the configured absolute path alone would miss.
  if (!exe.empty())
    add_unique(dirs, exe.parent_path().parent_path() / std::string(build::kProfileInstallRelative),
               "installed profiles");
  add_unique(dirs, std::string(build::kProfileInstallDir), "installed profiles");
  if (!exe.empty() && exe.parent_path() == fs::path(std::string(build::kBuildBinDir)))
    add_unique(dirs, std::string(build::kSourceProfileDir), "source tree");
  return dirs;
}

CLI::Validator profile_file() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        try {
          value = profile::locate_profile(value, profile_search_dirs()).string();
          return {};
        } catch (const profile::ProfileNotFound& e) {
          return e.what();
        }
      },
      "PROFILE", "profile file or name");
}

}  // namespace i20::cli
