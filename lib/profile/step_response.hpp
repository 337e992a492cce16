// SPDX-License-Identifier: GPL-2.0-or-later
// A simulated current step of the 8I20's PI loop on the motor's R-L winding.
//
// Model (a locked rotor, so no back-EMF; one axis of the dq frame):
//  - plant: L di/dt = v - R i, discretised exactly for a zero-order hold (lib/motor: the
//    same current loop and winding the virtual 8I20 drives its motor with);
//  - controller: discrete PI sampled at the PWM rate (default 12 kHz, the manual's
//    default switching frequency), its output applied one period later (computation delay);
//  - voltage limited to Vbus / sqrt(3), the largest phase voltage space-vector PWM makes
//    from the bus; the integrator stops while the output is limited (anti-windup);
//  - card gains are turned into volts per amp with the tuning model (tune.hpp), so this
//    shows what given KQP/KQI would do on this motor relative to the reference.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "profile/tune.hpp"

namespace i20::profile {

struct StepRequest {
  MotorModel motor;
  double max_current_a = 0;
  double bus_voltage_v = 0;
  std::int64_t kp = 0;  // card gains (KQP/KDP, KQI/KDI)
  std::int64_t ki = 0;
  ReferenceTuning reference;
  double step_a = 0;  // 0: half of MAXCURRENT
  double sample_rate_hz = 12000;
  double duration_s = 0;  // 0: long enough to settle, at most 10 of the loop's slowest time constants
};

struct StepSample {
  double t_s = 0;
  double command_a = 0;
  double current_a = 0;
  double voltage_v = 0;  // applied during this sample period
};

struct StepMetrics {
  std::optional<double> rise_start_s;     // when the response passes 10% of the step
  std::optional<double> rise_time_s;      // from there to 90% of the step
  double overshoot_pct = 0;               // peak above the step, in % of the step
  std::optional<double> settling_time_s;  // last time outside +-2% of the step
  double final_a = 0;
  double final_error_pct = 0;  // (step - final) / step
  bool saturated = false;      // the voltage limit was reached
};

struct StepResponse {
  std::vector<StepSample> samples;
  StepMetrics metrics;
  double step_a = 0;
  double voltage_limit_v = 0;
  PhysicalGains gains;  // the volts-per-amp gains simulated
};

// Throws TuneError for non-physical inputs (as tune() does).
StepResponse simulate_step(const StepRequest& request);

// The most overshoot the tool accepts from its own model. A PI current loop designed by
// pole-zero cancellation overshoots about 5% at the highest bandwidth tune() calls damped
// (wc*T = 0.35); 20% leaves room for gains rounded to whole counts and a reference that is
// not this motor, while a loop that rings harder than that is one the model calls unstable.
inline constexpr double kMaxAcceptedOvershootPct = 20.0;
// A step that ends further than this from its command has not settled.
inline constexpr double kMaxFinalErrorPct = 2.0;

// Whether the model calls these gains usable: the step settles within the simulated window
// and overshoots at most kMaxAcceptedOvershootPct. `reason` says why not, in one phrase.
struct LoopVerdict {
  bool acceptable = true;
  std::string reason;
};
LoopVerdict judge_step(const StepResponse& response);

// The verdict on card gains kp/ki (KQP/KQI or KDP/KDI) for this motor, MAXCURRENT and bus:
// the step simulate_step() draws, judged by judge_step(). Throws TuneError as it does.
LoopVerdict judge_gains(const MotorModel& motor, double max_current_a, double bus_voltage_v, std::int64_t kp,
                        std::int64_t ki, const ReferenceTuning& reference = {});

}  // namespace i20::profile
