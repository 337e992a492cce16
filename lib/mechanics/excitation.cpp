// SPDX-License-Identifier: GPL-2.0-or-later
#include "mechanics/excitation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "mechanics/identify.hpp"

namespace i20::mechanics {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kSlowestHz = 0.6;
constexpr double kFastestHz = 1.6;
constexpr double kRippleHz = 2.5;
constexpr double kRippleShare = 0.15;  // a = A x this: its speed stays below the slowest sweep's
constexpr double kUsedShare = 0.8;     // of the half window
constexpr double kEaseS = 0.5;
// The identification counts speeds above 0.5 rad/s as motion; the slowest sweep's peak must
// be well above that for most of each stroke to count.
constexpr double kLeastPeakSpeed = 3.0;

// 1/2 (1 - cos): 0 at 0, 1 at 1, zero slope at both ends.
double smooth(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return 0.5 * (1 - std::cos(std::numbers::pi * x));
}

std::string speed(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

std::string rad(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g rad (%.3g turn)", v, v / kTwoPi);
  return buf;
}

}  // namespace

double Excitation::least_half_travel_rad() {
  return kLeastPeakSpeed / (kTwoPi * kSlowestHz) / kUsedShare;
}

Excitation::Excitation(const ExcitationLimits& limits) : duration_(limits.duration_s) {
  if (!(limits.duration_s >= 4 * kEaseS))
    throw IdentifyError("an identification move needs at least " + std::to_string(4 * kEaseS) + " s");
  const double least = least_half_travel_rad();
  if (!(limits.half_travel_rad >= least))
    throw IdentifyError("a travel window of +-" + rad(limits.half_travel_rad) +
                        " is too short to identify in: allow at least +-" + rad(least));
  slow_ = kUsedShare * limits.half_travel_rad / (1 + kRippleShare);
  ripple_ = kRippleShare * slow_;
  // The fastest the path goes: both parts at their peaks (ease ignored: it only slows).
  const auto peak = [&](double a) { return a * kTwoPi * kFastestHz + a * kRippleShare * kTwoPi * kRippleHz; };
  if (limits.max_speed_rad_s > 0 && peak(slow_) > limits.max_speed_rad_s) {
    slow_ *= limits.max_speed_rad_s / peak(slow_);
    ripple_ = kRippleShare * slow_;
    if (slow_ * kTwoPi * kSlowestHz < kLeastPeakSpeed)
      throw IdentifyError("a speed limit of " + speed(limits.max_speed_rad_s) +
                          " rad/s leaves too little speed to identify friction: allow at least " +
                          speed(peak(kLeastPeakSpeed / (kTwoPi * kSlowestHz))) + " rad/s");
  }
  peak_speed_ = peak(slow_);
}

double Excitation::phase(double t) const {
  // The rate sweeps linearly from the slowest to the fastest: phi = 2 pi (f0 t + (f1 - f0) t^2 / 2T).
  return kTwoPi * (kSlowestHz * t + (kFastestHz - kSlowestHz) * t * t / (2 * duration_));
}

double Excitation::ease(double t) const {
  return smooth(t / kEaseS) * smooth((duration_ - t) / kEaseS);
}

double Excitation::position_rad(double t) const {
  if (t <= 0 || t >= duration_) return 0;
  return ease(t) * (slow_ * std::sin(phase(t)) + ripple_ * std::sin(kTwoPi * kRippleHz * t));
}

double Excitation::speed_rad_s(double t) const {
  const double h = 1e-5;
  return (position_rad(t + h) - position_rad(t - h)) / (2 * h);
}

double Excitation::acceleration_rad_s2(double t) const {
  const double h = 1e-4;
  return (position_rad(t + h) - 2 * position_rad(t) + position_rad(t - h)) / (h * h);
}

}  // namespace i20::mechanics
