// SPDX-License-Identifier: GPL-2.0-or-later
// The project version (CMakeLists.txt `project(... VERSION ...)`) and the install layout.
// Defined in build_info.cpp, which CMake configures from build_info.cpp.in: the paths stay
// out of every file that includes this one, so ccache hits for them in a clone elsewhere.
#pragma once

#include <string_view>

namespace i20::build {

// "0.1.0": what every program prints for --version.
extern const std::string_view kVersion;

// Where `cmake --install` puts the shipped profiles: absolute for the configured prefix,
// and relative to the prefix, so a program found at PREFIX/bin also finds them after the
// tree was moved (a staging root, a relocated package).
extern const std::string_view kProfileInstallDir;
extern const std::string_view kProfileInstallRelative;

// A program running from this build tree's bin/ also finds the source tree's profiles/.
extern const std::string_view kBuildBinDir;
extern const std::string_view kSourceProfileDir;

// Helper programs i20 runs (i20-halrun-virtual, for `i20 hal lint --load`): installed in
// PREFIX/libexec/i20tools; from the build tree, the source tree's apps/halrun-virtual.
extern const std::string_view kLibexecInstallDir;
extern const std::string_view kLibexecInstallRelative;
extern const std::string_view kSourceLibexecDir;

}  // namespace i20::build
