// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/locate.hpp"

#include <set>
#include <system_error>

namespace i20::profile {
namespace {

namespace fs = std::filesystem;

bool is_file(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// NAME, then NAME.yaml: "line-120v" and "line-120v.yaml" both name the shipped file.
std::vector<fs::path> candidates(const fs::path& dir, const std::string& name) {
  std::vector<fs::path> paths{dir / name};
  if (fs::path(name).extension() != ".yaml") paths.push_back(dir / (name + ".yaml"));
  return paths;
}

std::string tried_text(const std::string& name, const std::vector<SearchDir>& search) {
  std::string text = "profile '" + name + "' not found: tried " + name;
  for (const auto& s : search) text += ", " + (s.dir / name).string() + "[.yaml] (" + s.origin + ")";
  if (search.empty()) text += " (no profile directories: set I20_PROFILE_PATH)";
  return text;
}

}  // namespace

fs::path locate_profile(const std::string& name_or_path, const std::vector<SearchDir>& search) {
  if (is_file(name_or_path)) return name_or_path;
  // A name with a directory part is a path the user meant literally.
  const bool bare_name = fs::path(name_or_path).filename() == fs::path(name_or_path);
  if (bare_name && !name_or_path.empty())
    for (const auto& s : search)
      for (const auto& path : candidates(s.dir, name_or_path))
        if (is_file(path)) return path;
  // Something that is there but no file (a directory, /dev/zero): the reader says why it
  // is refused, which helps more than "not found".
  if (std::error_code ec; fs::exists(name_or_path, ec)) return name_or_path;
  if (!bare_name) throw ProfileNotFound("profile file '" + name_or_path + "' does not exist");
  throw ProfileNotFound(tried_text(name_or_path, search));
}

std::vector<std::string> profile_names(const std::vector<SearchDir>& search) {
  std::set<std::string> names;
  for (const auto& s : search) {
    std::error_code ec;
    for (fs::directory_iterator it(s.dir, ec), end; !ec && it != end; it.increment(ec))
      if (it->path().extension() == ".yaml" && is_file(it->path())) names.insert(it->path().stem().string());
  }
  return {names.begin(), names.end()};
}

}  // namespace i20::profile
