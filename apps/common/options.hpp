// SPDX-License-Identifier: GPL-2.0-or-later
// The global options every app parses (where the 8I20 is, which database, how to print):
// the session's options plus the apps' own output switches.
#pragma once

#include "errors.hpp"
#include "ops/core/session.hpp"

namespace CLI {
class App;
}

namespace i20::app {

struct GlobalOptions : ops::SessionOptions {
  bool json = false;
  bool verbose = false;
};

// Adds --port/--sim/--eth/... to an app (the i20 umbrella, wpd, rpd).
void add_target_options(CLI::App& app, GlobalOptions& options);
void add_database_options(CLI::App& app, GlobalOptions& options);

// The override options `command` really has, by their names on it or on a parent (i20's
// global options): what advice may name (set_overrides).
Overrides overrides_of(const CLI::App& command);
// The same for the command the parsed arguments chose (the deepest subcommand given).
Overrides overrides_of_parsed(const CLI::App& app);

}  // namespace i20::app
