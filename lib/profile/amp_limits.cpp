// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/amp_limits.hpp"

#include <cstdio>

#include "faults/fault_table.hpp"

namespace i20::profile {

double amp_max_bus_v() {
  // Throws if the compiled-in table lost the limit: a missing safety check must not pass.
  static const double limit = faults::FaultTable::builtin().fixed_limit("max-bus-voltage");
  return limit;
}

std::string limit_text(double value, const char* unit) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%g %s", value, unit);
  return buf;
}

}  // namespace i20::profile
