// SPDX-License-Identifier: GPL-2.0-or-later
// Builds the simulator's register map from the project's parameter database, so the
// simulated card follows params/8i20.yaml (or any YAML given with --params).
#pragma once

#include "params/param_db.hpp"
#include "sim/register_map.hpp"

namespace i20::sim {

// Every parameter with a known address becomes a register; a default the database does
// not give is taken from RegisterMap::builtin() (e.g. NVMAXCURRENT 1000 = 10 A). The
// reported SWREVISION is the database's `simulator_swrevision` (else 0xE120).
// Throws ConfigError if the result is not a usable map.
RegisterMap register_map_from(const params::ParamDb& db);

}  // namespace i20::sim
