// SPDX-License-Identifier: GPL-2.0-or-later
// The values a bldc HAL fragment needs from the analysis, in bldc's own units. The HAL text
// itself is written elsewhere.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "commission/result.hpp"

namespace i20::commission {

struct BldcSettings {
  std::optional<int> pattern;                  // `pattern` (h, qh, qhi), when its number is known
  std::optional<HallRewiring> hall_rewiring;   // feed hall1..3 this way when pattern is 25 by rewiring
  std::optional<int> poles;                    // `poles`: the number of poles, 2 x pole pairs
  std::optional<std::int64_t> scale;           // `scale`: encoder direction x counts per turn
  std::optional<std::int64_t> encoder_offset;  // `encoder-offset` (qi, qhi)
  std::vector<std::string> missing;            // why each absent value is absent
};

BldcSettings bldc_settings(const CommutationResult& result);

}  // namespace i20::commission
