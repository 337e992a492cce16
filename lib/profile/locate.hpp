// SPDX-License-Identifier: GPL-2.0-or-later
// Finding a profile by name: `i20 profile apply line-120v` from any directory.
//
// Search order: the argument as a path, if that file exists; then each directory of the
// search list in order (the caller builds it: $I20_PROFILE_PATH, the installed
// share/i20tools/profiles, the source tree's profiles/ for build-tree runs), trying NAME
// and NAME.yaml in each. Pure apart from asking the file system what exists.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "error/error.hpp"

namespace i20::profile {

// One place to look, and why it is on the list (shown when nothing is found).
struct SearchDir {
  std::filesystem::path dir;
  std::string origin;  // e.g. "$I20_PROFILE_PATH", "installed profiles"
};

// Nothing found. what() names every place that was tried, in order.
class ProfileNotFound : public Error {
 public:
  explicit ProfileNotFound(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

// The file `name_or_path` stands for. Throws ProfileNotFound.
std::filesystem::path locate_profile(const std::string& name_or_path, const std::vector<SearchDir>& search);

// The profile names a search list offers: each *.yaml file name without the extension,
// once, sorted.
std::vector<std::string> profile_names(const std::vector<SearchDir>& search);

}  // namespace i20::profile
