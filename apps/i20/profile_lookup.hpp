// SPDX-License-Identifier: GPL-2.0-or-later
// Where `i20 profile ... NAME` looks for NAME: the path itself, then $I20_PROFILE_PATH
// (colon-separated directories), then the installed share/i20tools/profiles, then the
// source tree's profiles/ when the program runs from its build tree.
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <vector>

#include "profile/locate.hpp"

namespace i20::cli {

// This program's own path (/proc/self/exe), empty when unknown: installed files are found
// relative to it.
std::filesystem::path own_executable();

// The directories in search order, for this process (environment and executable location).
std::vector<profile::SearchDir> profile_search_dirs();

// A CLI11 transform for profile FILE arguments: replaces a name with the file it finds, or
// fails naming every place it tried.
CLI::Validator profile_file();

}  // namespace i20::cli
