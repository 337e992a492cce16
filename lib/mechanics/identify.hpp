// SPDX-License-Identifier: GPL-2.0-or-later
// Identifying an axis's mechanics from a gentle back-and-forth move (issue 43): the total
// inertia at the motor shaft, its viscous and Coulomb friction and a constant bias (a
// vertical axis's weight), each with its uncertainty. Pure: numbers in, numbers out.
//
// The model, at the motor shaft (what a position loop below the first resonance sees):
//
//   T = J dw/dt + B w + Tc sign(w) + G
//
// T is the torque commanded (Kt x the current command; the 8I20's current loop is far faster
// than the windows below), w the shaft's speed, G the bias (positive: it opposes forward
// motion, as a motor file's `load`). Differentiating an encoder twice amplifies its
// quantization, so the equation is integrated over short windows [a, b] instead:
//
//   sum T dt = J (w_b - w_a) + B (theta_b - theta_a) + Tc sum sign(w) dt + G (b - a)
//
// with the speeds at the window's edges from a centred difference of the position. Windows
// where the shaft reverses or creeps (stick-slip, which the model does not describe) are left
// out. Least squares over the windows gives the four values and, from the residuals, their
// standard deviations.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "error/error.hpp"

namespace i20::mechanics {

// The move could not determine the mechanics (too short, one way only, too alike
// throughout); the message says what the move lacked. Nothing about the card is uncertain.
class IdentifyError : public Error {
 public:
  explicit IdentifyError(const std::string& message) : Error(message, ErrorKind::Failure) {}
};

// One servo period's record: when, where the encoder put the shaft, what torque was asked for
// during the period that starts there (held until the next sample).
struct MotionSample {
  double time_s = 0;
  double position_rad = 0;  // motor shaft, unwrapped
  double torque_nm = 0;
};

struct Estimate {
  double value = 0;
  double sigma = 0;  // one standard deviation, from the fit's residuals
};

struct Mechanics {
  Estimate inertia_kgm2;
  Estimate viscous_nm_per_rad_s;
  Estimate coulomb_nm;
  Estimate bias_nm;          // + opposes forward motion (gravity on a vertical axis)
  std::size_t windows = 0;   // used in the fit
  double residual_nm_s = 0;  // RMS of the fit's residuals (torque x time per window)
};

struct IdentifyOptions {
  double window_s = 0.02;          // length of each integration window
  double speed_span_s = 0.004;     // a centred difference over +-this gives a speed
  double least_speed_rad_s = 0.5;  // below it in a window: creeping, left out
};

// Throws IdentifyError when the samples cannot determine all four values (too few
// windows, motion in one direction only, no change of speed): the message says which.
Mechanics identify(std::span<const MotionSample> samples, const IdentifyOptions& options = {});

// One window of the fit, as the mean torque over it: what the record says was asked for (its
// sum T dt over the window's length) and what the mechanics `m` give for the window's motion
// (J dw + B dtheta + Tc sign(w) dt + G dt, over the same length). Where the two part, the
// model does not describe the axis there: what a plot of the fit shows.
struct FitWindow {
  double from_s = 0, to_s = 0;
  double recorded_nm = 0;
  double fitted_nm = 0;
};

// The windows identify() fits (the same windows, speeds and options), each with the torque `m`
// gives. Throws IdentifyError as identify() does for samples it cannot cut into windows.
std::vector<FitWindow> fit_windows(std::span<const MotionSample> samples, const Mechanics& m,
                                   const IdentifyOptions& options = {});

}  // namespace i20::mechanics
