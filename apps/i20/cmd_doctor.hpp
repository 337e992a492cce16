// SPDX-License-Identifier: GPL-2.0-or-later
// i20 doctor: LinuxCNC's output about an 8I20 axis explained (apps/i20/cmd_doctor.cpp).
#pragma once

#include "context.hpp"

namespace i20::cli {

void register_doctor_command(CLI::App& app, Context& ctx);

}  // namespace i20::cli
