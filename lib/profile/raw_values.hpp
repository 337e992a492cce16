// SPDX-License-Identifier: GPL-2.0-or-later
// Raw values by database name ("NVBRAKEONV" -> 36000): what a card holds, or will.
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace i20::profile {

using RawValues = std::map<std::string, std::int64_t>;

}  // namespace i20::profile
