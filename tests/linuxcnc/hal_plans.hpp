// SPDX-License-Identifier: GPL-2.0-or-later
// The plans the HAL tests generate files from, and the power-up delays the program writes
// (ops/core/timing.hpp): one place for the generator's, the linter's and the INI check's tests.
#pragma once

#include <string>

#include "linuxcnc/hal_generate.hpp"
#include "ops/core/timing.hpp"

namespace i20::linuxcnc::test {

inline const PowerUpDelays kProgramDelays{i20::ops::timing::kHalPortRunDelay,
                                          i20::ops::timing::kHalFaultWatchDelay};

// Halls and encoder (cfg qh), pattern 17, 8 poles, 4,000 counts, MAXCURRENT 12 A; axis k's
// Halls on the 7I96S's isolated inputs 3k..3k+2.
inline HalPlan hall_encoder_plan(int axes = 1) {
  HalPlan p;
  p.axes = axes;
  p.cfg = "qh";
  p.pattern = 17;
  p.poles = 8;
  p.counts_per_rev = 4000;
  p.max_current = 12.0;
  for (int k = 0; k < axes; ++k)
    p.halls.push_back("hm2_7i96s.0.inm.00.input-0" + std::to_string(3 * k) + ",hm2_7i96s.0.inm.00.input-0" +
                      std::to_string(3 * k + 1) + ",hm2_7i96s.0.inm.00.input-0" + std::to_string(3 * k + 2));
  return p;
}

}  // namespace i20::linuxcnc::test
