// SPDX-License-Identifier: GPL-2.0-or-later
// What the commissioning sweep records each servo period, and what the user may tell the
// analysis beforehand.
#pragma once

#include <cstdint>
#include <optional>

#include "commission/hall_table.hpp"

namespace i20::commission {

// One servo period of the sweep.
//
// The commanded angle is the electrical angle the drive's current vector points to, in
// bldc's convention (0 = where an unloaded rotor settles with A at +V and B, C at -V; 1.0 =
// one electrical turn; forward = increasing angle, phase order A->B->C). It is cumulative: a
// sweep of three turns forward runs from a to a+3, not round 0..1 three times (a jump of more
// than half a turn between two samples is taken as a wrap and undone).
struct Sample {
  double t_s = 0;                         // time since the start of the sweep
  double commanded_electrical_turns = 0;  // cumulative
  std::int64_t encoder_count = 0;         // raw, 64-bit extended (hm2 `rawcounts`)
  HallCode hall_state = 0;                // H1*4 + H2*2 + H3
  // The index latched in this period (the procedure re-arms the latch every period, so each
  // pass shows once) at this raw count; latched_count is valid only when index_seen.
  bool index_seen = false;
  std::int64_t latched_count = 0;
};

// Options outside their range (pole pairs or counts below 1, a negative settle) are a
// UsageError from analyse().
struct AnalysisOptions {
  std::optional<int> pole_pairs;                   // pairs, not poles (bldc's `poles` = 2x)
  std::optional<std::int64_t> counts_per_turn;     // encoder counts per mechanical turn (lines x 4)
  std::optional<HallLayout> expected_hall_layout;  // a hint: a different finding is reported
  bool hall_sensors_expected = true;               // false: no Hall problems are reported
  // Command travel ignored at the start of each sweep while friction, backlash and the
  // alignment transient settle (electrical turns).
  double settle_turns = 0.5;
};

}  // namespace i20::commission
