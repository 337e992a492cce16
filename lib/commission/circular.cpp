// SPDX-License-Identifier: GPL-2.0-or-later
#include "commission/circular.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace i20::commission {

namespace {
constexpr double kTau = 2.0 * std::numbers::pi;
}

double wrap_turns(double turns) {
  const double wrapped = turns - std::floor(turns);
  return wrapped >= 1.0 ? 0.0 : wrapped;  // -1e-18 floors to -1 and gives 1.0
}

double wrap_signed(double turns) {
  return wrap_turns(turns + 0.5) - 0.5;
}

double circular_midpoint(double a_turns, double b_turns) {
  return wrap_turns(a_turns + wrap_signed(b_turns - a_turns) / 2.0);
}

void CircularMean::add(double turns, double weight) {
  sum_cos_ += weight * std::cos(kTau * turns);
  sum_sin_ += weight * std::sin(kTau * turns);
  sum_weight_ += weight;
  ++count_;
}

double CircularMean::mean_turns() const {
  if (empty()) return 0.0;
  return wrap_turns(std::atan2(sum_sin_, sum_cos_) / kTau);
}

double CircularMean::resultant() const {
  if (sum_weight_ <= 0.0) return 0.0;
  return std::hypot(sum_cos_, sum_sin_) / sum_weight_;
}

double CircularMean::deviation_turns() const {
  const double r = resultant();
  if (r <= 0.0) return 0.5;
  return std::sqrt(std::max(0.0, -2.0 * std::log(std::min(1.0, r)))) / kTau;
}

}  // namespace i20::commission
