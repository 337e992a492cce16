// SPDX-License-Identifier: GPL-2.0-or-later
// i20 inventory: the fleet, read-only (cmd_inventory.cpp).
#pragma once

namespace CLI {
class App;
}

namespace i20::cli {

struct Context;
void register_inventory_command(CLI::App& app, Context& ctx);

}  // namespace i20::cli
