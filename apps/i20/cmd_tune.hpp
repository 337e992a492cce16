// SPDX-License-Identifier: GPL-2.0-or-later
// i20 tune: current-loop gains from the motor's R and L (see profiles/TUNING.md).
#pragma once

namespace CLI {
class App;
}

namespace i20::cli {

struct Context;

// Registered by register_profile_commands (context.hpp: "profile, tune").
void register_tune_command(CLI::App& app, Context& ctx);

}  // namespace i20::cli
