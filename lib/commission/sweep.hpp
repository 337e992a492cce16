// SPDX-License-Identifier: GPL-2.0-or-later
// The sweep's shape, read from the command alone: runs of samples where the commanded angle
// rises (forward) or falls (backward), and within each run the "steady" samples after the
// command has moved far enough for friction, backlash and the alignment to settle.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "commission/sample.hpp"

namespace i20::commission {

struct SweepRun {
  int direction = 0;              // +1 forward, -1 backward
  std::size_t steady_begin = 0;   // first steady sample
  std::size_t end = 0;            // one past the last sample
  double steady_start_turns = 0;  // the command where the steady part starts
};

struct Sweep {
  std::vector<double> command;  // unwrapped, per sample
  std::vector<SweepRun> runs;   // only runs with a steady part
  double steady_travel(int direction) const;
  std::size_t steady_count(int direction) const;
};

Sweep read_sweep(std::span<const Sample> samples, double settle_turns);

}  // namespace i20::commission
