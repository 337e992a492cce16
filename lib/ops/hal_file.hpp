// SPDX-License-Identifier: GPL-2.0-or-later
// The use case of `i20 hal`: a LinuxCNC HAL file for 8I20 axes, from the plan the front end
// parsed (board, axes, cfg, commutation, MAXCURRENT). Needs no card.
#pragma once

#include <string>

#include "linuxcnc/hal_generate.hpp"

namespace i20::ops {

// The plan checked (UsageError naming what is wrong), the file generated, and the file
// proved against the linter's own rules before anyone gets it: a finding there is a defect
// of this tool (Error), never handed on as a file.
std::string generate_hal_file(const linuxcnc::HalPlan& plan);

}  // namespace i20::ops
