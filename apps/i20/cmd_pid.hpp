// SPDX-License-Identifier: GPL-2.0-or-later
// i20 pid: LinuxCNC pid gains designed from an axis's mechanics (apps/i20/cmd_pid.cpp).
#pragma once

#include "context.hpp"

namespace i20::cli {

void register_pid_command(CLI::App& app, Context& ctx);

}  // namespace i20::cli
