// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/profile_diff.hpp"

#include <algorithm>

namespace i20::ops {

long ProfileDiff::differ() const {
  return std::ranges::count_if(rows, [](const profile::DiffRow& r) { return !r.equal && r.card_raw; });
}

long ProfileDiff::unknown() const {
  return std::ranges::count_if(rows, [](const profile::DiffRow& r) { return !r.card_raw; });
}

Comparison ProfileDiff::comparison() const {
  if (interrupted) return Comparison::Interrupted;
  if (!error.empty() || unknown() > 0) return Comparison::Trouble;
  return differ() > 0 ? Comparison::Differs : Comparison::Same;
}

}  // namespace i20::ops
