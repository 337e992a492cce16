// SPDX-License-Identifier: GPL-2.0-or-later
// Where the source tree and the built programs are, for the tests and the benchmarks.
//
// The paths live in one generated object (build_paths.cpp, configured by CMake) rather than
// in compile definitions: an absolute path on every test's command line made each test
// object differ between two clones, so ccache missed all of them in a clone at a new folder.
#pragma once

#include <filesystem>

namespace i20::test {

// The checkout the build was configured from (params/, motors/, tests/*/data, ...).
std::filesystem::path source_dir();
// build/bin: i20, wpd, rpd, i20sim and the benchmarks.
std::filesystem::path bin_dir();

}  // namespace i20::test
