// SPDX-License-Identifier: GPL-2.0-or-later
// i20 profile export FILE --hal | --setsserial: a profile's NV values for LinuxCNC.
#pragma once

namespace CLI {
class App;
}

namespace i20::cli {

struct Context;

// Adds `export` under the `profile` subcommand.
void register_profile_export(CLI::App& profile, Context& ctx);

}  // namespace i20::cli
