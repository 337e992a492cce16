// SPDX-License-Identifier: GPL-2.0-or-later
// LinuxCNC's pid with given gains on the motor model (lib/motor, with its machine), following
// a trapezoidal move as limit3 or motion would give it: what `i20 pid` draws and the tests
// judge. Each servo period it reads the encoder (or the ideal angle without one), computes
// pid as LinuxCNC does (bias, P, the integral of error x period, D of two periods' errors,
// FF1 and FF2 from the command's differences, the output limited to maxoutput), and the 8I20
// gets that current one period later (the design's delay). Pure: the caller's clock.
#pragma once

#include <random>
#include <vector>

#include "mechanics/excitation.hpp"
#include "mechanics/identify.hpp"
#include "mechanics/pid_design.hpp"
#include "motor/params.hpp"

namespace i20::mechanics {

// Out by `distance` machine units and back, each leg a trapezoid (speed, acceleration), with
// `dwell_s` at rest after each.
struct MoveProfile {
  double distance = 10;
  double speed = 20;
  double accel = 500;
  double dwell_s = 0.5;
  double duration_s() const;
  double position(double t) const;
};

struct TracePoint {
  double time_s = 0;
  double command = 0;    // machine units
  double position = 0;   // as the encoder read it
  double error = 0;      // command - position
  double current_a = 0;  // pid's output, as written
};

struct MoveTrace {
  std::vector<TracePoint> points;
  double peak_error = 0;  // while moving and dwelling, machine units
  double rms_error = 0;
  double rest_error = 0;  // the largest in the last quarter of the final dwell
};

// `units_per_rad`: machine units per motor radian. `gain_scale` multiplies P, I and D (a
// margin's check). Throws IdentifyError for a model the motor cannot be.
MoveTrace simulate_move(const motor::MotorParams& truth, const PidGains& gains, double units_per_rad,
                        const MoveProfile& move, const LoopTiming& timing = {}, double gain_scale = 1);

// An identification move rehearsed on the motor model: a gentle PID loop of the tool's own
// (4 Hz for the guessed inertia, or stiffer against the guessed friction, so that friction
// holds the shaft back by at most a tenth of the path's reach; its speed feedback and its
// torque low-passed at 20 Hz so that it does not drive a resonance above) follows the
// excitation at the servo period and records what an 8I20 axis's host would: the encoder's
// position and the torque it asked for. The truth needs an encoder.
struct Rehearsal {
  std::vector<MotionSample> samples;
  double widest_rad = 0;  // the farthest the shaft went from where it started
};
Rehearsal rehearse_identification(const motor::MotorParams& truth, const Excitation& path,
                                  double inertia_guess, double friction_guess, double servo_period_s = 1e-3);

// The axis the design sees in a motor model: its total inertia, friction, load torque as the
// bias, torque constant, and, where the model has a compliant coupling, the resonance with the
// rotor's own inertia and the coupling's damping ratio (two masses). `units_per_rad`: machine
// units per motor radian. The one translation for `i20 pid --motor`, the benchmark and the tests.
AxisModel axis_model_of(const motor::MotorParams& truth, double units_per_rad, double max_current_a);

// A random vertical axis for tests and benchmarks: the 400 W servo (10,000-count encoder) on
// a 5 mm screw, load inertia 1-20 times the rotor's, Coulomb friction 0.01-0.08 Nm, viscous
// up to 1 mNm/(rad/s), a bias (gravity) of +-0.5 Nm, a coupling resonating at 50-400 Hz
// (raised where needed to keep the anti-resonance at 30 Hz or more: softer machines need a
// sweep before a rigid-body fit, not done yet) with 5% damping.
motor::MotorParams random_vertical_axis(std::mt19937_64& random);

}  // namespace i20::mechanics
