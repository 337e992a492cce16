// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal lint --ini FILE`: the HAL files' INI references held against the configuration's
// INI (pure: the texts in, findings out).
//
// - ini-missing (error, halcmd refuses the line): a `[SECTION]KEY` the INI does not have.
//   halcmd run with the INI stops there ("Ini variable '[JOINT_0]NOTCH_N0' not found.",
//   checked with LinuxCNC 2.9's halrun -i).
// - ini-notch-not-run (warning): a [JOINT_k] with the notch `i20 pid --notch` designs
//   (NOTCH_N0..NOTCH_D2) that no HAL line reads: the gains were designed for a loop with the
//   notch, and LinuxCNC would run them without it (docs/axis-tuning.md).
//
// The INI as LinuxCNC reads it: `[SECTION]` lines, `KEY = VALUE` lines, `#` and `;` comments.
#pragma once

#include <string>
#include <vector>

#include "linuxcnc/hal_file.hpp"
#include "linuxcnc/hal_lint.hpp"

namespace i20::linuxcnc {

std::vector<LintFinding> check_ini(const std::vector<Statement>& statements, const std::string& ini_text,
                                   const std::string& ini_file);

}  // namespace i20::linuxcnc
