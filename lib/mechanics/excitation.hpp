// SPDX-License-Identifier: GPL-2.0-or-later
// The path an identification move follows (issue 43): back and forth within the travel window
// the user allows, at a range of speeds (friction's viscous part shows against its Coulomb
// part) with a faster ripple on top (inertia shows against friction), easing in and out so
// the move starts and ends at rest where it began. Pure: a function of time.
//
//   position(t) = e(t) [A sin(phi(t)) + a sin(2 pi f_r t)]
//
// with phi's rate sweeping from 0.6 to 1.6 Hz over the move, a = 0.15 A at f_r = 2.5 Hz (its
// speed stays below the sweep's), and e(t) a smooth ramp over the first and last 0.5 s. A + a is at most
// kUsedShare of the half window: the rest is room for the loop's following error.
#pragma once

namespace i20::mechanics {

struct ExcitationLimits {
  double half_travel_rad = 0;  // the window: +-this about where the move starts (motor shaft)
  double duration_s = 8;
  double max_speed_rad_s = 0;  // 0: no limit of the user's
};

class Excitation {
 public:
  // Throws IdentifyError when the window is too short to identify in (it says the least that
  // would do) or the speed limit leaves too little speed.
  explicit Excitation(const ExcitationLimits& limits);

  double position_rad(double t) const;
  double speed_rad_s(double t) const;  // numerically exact derivative of position
  double acceleration_rad_s2(double t) const;
  double duration_s() const { return duration_; }
  double peak_speed_rad_s() const { return peak_speed_; }
  double amplitude_rad() const { return slow_ + ripple_; }

  // The smallest half window a move of this kind can identify in: the slowest sweep must
  // reach a speed the identification counts as motion, with room to spare.
  static double least_half_travel_rad();

 private:
  double phase(double t) const;
  double ease(double t) const;
  double duration_;
  double slow_ = 0;    // A
  double ripple_ = 0;  // a
  double peak_speed_ = 0;
};

}  // namespace i20::mechanics
