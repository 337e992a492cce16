// SPDX-License-Identifier: GPL-2.0-or-later
// i20-soak --eth: the soak's scenarios and judge over the Ethernet path (soak_eth.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "params/param_db.hpp"

namespace i20::soak {

// Runs scenario K of the N a seed draws for every K (or the K in `only`), prints the table;
// returns the exit code (1 when a must-be-0 column is not 0).
int run_eth_soak(std::size_t n, std::uint64_t seed, const std::vector<std::size_t>& only,
                 const params::ParamDb& db, bool verbose);

}  // namespace i20::soak
