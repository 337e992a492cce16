// SPDX-License-Identifier: GPL-2.0-or-later
// "Pending" NV values: EEPROM cells whose working twin holds something else, i.e. what the
// next reset (or power-up) makes live (manual: NV values become the working values at
// power-up and after a software reset). The one definition behind apply's and set's "not
// live yet", the report's list and the reset judgement.
#pragma once

#include <string>
#include <vector>

#include "ops/core/amp.hpp"
#include "params/param_db.hpp"
#include "profile/raw_values.hpp"

namespace i20::ops {

// The NV cells a reset copies into a working twin the database knows, in database order.
std::vector<const params::Param*> nv_cells_with_twins(const params::ParamDb& db);

// NV cells whose value in `values` differs from their working twin's; only pairs whose both
// cells are in `values` count. In database order.
std::vector<std::string> pending_nv_values(const params::ParamDb& db, const profile::RawValues& values);

// The same for the whole card: reads every NV cell that has a working twin, and the twins
// (cells that are no fact on this firmware are left out, so never called pending). Throws
// what the reads throw.
std::vector<std::string> pending_nv_values(Amp& amp);

}  // namespace i20::ops
