// SPDX-License-Identifier: GPL-2.0-or-later
// Circular statistics on angles in turns (1.0 = one electrical revolution): an average of
// angles that straddle zero must not land half a turn away, so angles are averaged as unit
// vectors (the same way VESC averages its Hall states and encoder offset).
#pragma once

#include <cstddef>

namespace i20::commission {

// The angle brought into [0, 1).
double wrap_turns(double turns);
// The angle brought into [-0.5, 0.5): the signed shortest way from 0.
double wrap_signed(double turns);
// The point half way along the shorter arc from a to b, in [0, 1).
double circular_midpoint(double a_turns, double b_turns);

// Sums unit vectors; the mean is their direction, the resultant length (0-1) how tightly
// they agree (1 = all equal).
class CircularMean {
 public:
  void add(double turns, double weight = 1.0);
  std::size_t count() const { return count_; }
  bool empty() const { return count_ == 0; }
  double mean_turns() const;  // [0, 1); 0 when empty
  double resultant() const;   // 0..1
  // The circular standard deviation sqrt(-2 ln R), in turns.
  double deviation_turns() const;

 private:
  double sum_cos_ = 0;
  double sum_sin_ = 0;
  double sum_weight_ = 0;
  std::size_t count_ = 0;
};

}  // namespace i20::commission
