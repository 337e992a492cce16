// SPDX-License-Identifier: GPL-2.0-or-later
// Where the console's pages are: the source tree's share/console for a program run from
// this build tree's bin/, the installed share folder otherwise. Defined in console_paths.cpp,
// which CMake configures from console_paths.cpp.in (the paths stay out of the includers).
#pragma once

#include <string_view>

namespace i20::console::paths {

extern const std::string_view kSourceDir;
extern const std::string_view kInstallDir;
extern const std::string_view kInstallRelative;
extern const std::string_view kBuildBinDir;

}  // namespace i20::console::paths
