// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/step_response.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "motor/current_loop.hpp"
#include "profile/error.hpp"

namespace i20::profile {
namespace {

constexpr std::size_t kMinSamples = 24;
constexpr double kTimeConstants = 6.0;  // a first-order loop is within 0.25% by then
constexpr std::size_t kMaxSamples = 200000;
constexpr double kSettleBand = 0.02;
// A loop that has not settled after this many of its slowest time constants never will:
// simulating on (up to kMaxSamples, 16.7 s) only stretches the plot's time axis.
constexpr double kSettleWindows = 10.0;

void require_positive(double value, const char* what) {
  if (!(value > 0) || !std::isfinite(value))
    throw TuneError(std::string(what) + " must be a positive number");
}

// Simulates `count` samples of the loop: the motor model's PI current loop and winding
// (lib/motor/current_loop.hpp, the virtual 8I20's too) on a locked rotor, the step on the
// q axis alone.
struct Loop {
  MotorModel motor;
  PhysicalGains gains;
  double period = 0, vmax = 0, step = 0;

  std::vector<StepSample> run(std::size_t count) const {
    std::vector<StepSample> out;
    out.reserve(count);
    motor::Winding winding(motor, 0);  // a locked rotor has no back-EMF
    motor::PiCurrentLoop controller;
    double applied = 0;
    for (std::size_t k = 0; k < count; ++k) {
      const double i = winding.current().q;
      out.push_back({static_cast<double>(k) * period, step, i, applied});
      const auto next = controller.update({0, step - i}, gains, gains, period, vmax);
      winding.step({0, applied}, 0, period);  // the plant sees last period's output
      applied = next.voltage.q;
    }
    return out;
  }
};

// Time at which the response first crosses `level`, interpolated between samples.
std::optional<double> crossing(const std::vector<StepSample>& s, double level) {
  for (std::size_t k = 1; k < s.size(); ++k)
    if (s[k].current_a >= level && s[k - 1].current_a < level) {
      const double f = (level - s[k - 1].current_a) / (s[k].current_a - s[k - 1].current_a);
      return s[k - 1].t_s + f * (s[k].t_s - s[k - 1].t_s);
    }
  return std::nullopt;
}

StepMetrics measure(const std::vector<StepSample>& s, double step, double vmax) {
  StepMetrics m;
  const auto t10 = crossing(s, 0.1 * step);
  const auto t90 = crossing(s, 0.9 * step);
  m.rise_start_s = t10;
  if (t10 && t90) m.rise_time_s = *t90 - *t10;
  double peak = 0;
  for (const auto& x : s) {
    peak = std::max(peak, x.current_a);
    m.saturated = m.saturated || std::abs(x.voltage_v) >= vmax * (1 - 1e-12);
  }
  m.overshoot_pct = std::max(0.0, (peak - step) / step * 100.0);
  std::size_t last_out = s.size();
  for (std::size_t k = s.size(); k-- > 0;)
    if (std::abs(s[k].current_a - step) > kSettleBand * step) {
      last_out = k;
      break;
    }
  if (last_out == s.size())
    m.settling_time_s = 0.0;
  else if (last_out + 1 < s.size())
    m.settling_time_s = s[last_out + 1].t_s;
  m.final_a = s.back().current_a;
  m.final_error_pct = (step - m.final_a) / step * 100.0;
  return m;
}

// The slowest of: the closed loop (L / Kp), the winding (L / R), the integrator's zero
// (Kp / Ki, which hand-set gains may put far from the winding's pole) and the ramp at the
// voltage limit (L * step / Vmax, a large step on a low bus).
double slowest_time_constant(const Loop& loop, const MotorModel& motor) {
  const double kp = loop.gains.kp_v_per_a, ki = loop.gains.ki_v_per_as;
  double slowest = std::max(motor.inductance_h / kp, motor.inductance_h / motor.resistance_ohm);
  if (ki > 0) slowest = std::max(slowest, kp / ki);
  return std::max(slowest, motor.inductance_h * loop.step / loop.vmax);
}

std::string percent(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f%%", value);
  return buf;
}

}  // namespace

LoopVerdict judge_step(const StepResponse& response) {
  const StepMetrics& m = response.metrics;
  const bool settled = m.settling_time_s && std::abs(m.final_error_pct) <= kMaxFinalErrorPct;
  const bool overshoots = m.overshoot_pct > kMaxAcceptedOvershootPct;
  if (settled && !overshoots) return {};
  std::string reason = "the model's current step ";
  if (overshoots)
    reason += "overshoots " + percent(m.overshoot_pct) + " (at most " + percent(kMaxAcceptedOvershootPct) +
              " is accepted)";
  if (overshoots && !settled) reason += " and ";
  if (!settled) {
    char buf[64];
    const double window_ms = response.samples.empty() ? 0 : response.samples.back().t_s * 1e3;
    std::snprintf(buf, sizeof buf, "does not settle within %.3g ms", window_ms);
    reason += buf;
  }
  return {false, reason};
}

LoopVerdict judge_gains(const MotorModel& motor, double max_current_a, double bus_voltage_v, std::int64_t kp,
                        std::int64_t ki, const ReferenceTuning& reference) {
  StepRequest request;
  request.motor = motor;
  request.max_current_a = max_current_a;
  request.bus_voltage_v = bus_voltage_v;
  request.kp = kp;
  request.ki = ki;
  request.reference = reference;
  return judge_step(simulate_step(request));
}

StepResponse simulate_step(const StepRequest& r) {
  require_positive(r.motor.resistance_ohm, "the motor's phase resistance");
  require_positive(r.motor.inductance_h, "the motor's phase inductance");
  require_positive(r.max_current_a, "MAXCURRENT");
  require_positive(r.bus_voltage_v, "the bus voltage");
  require_positive(r.sample_rate_hz, "the loop sample rate");
  if (r.kp <= 0 || r.ki < 0) throw TuneError("the gains to simulate must be positive");
  StepResponse out;
  out.step_a = r.step_a > 0 ? r.step_a : 0.5 * r.max_current_a;
  out.voltage_limit_v = motor::voltage_limit(r.bus_voltage_v);
  out.gains = physical_gains(r.kp, r.ki, r.max_current_a, r.bus_voltage_v, r.reference);

  Loop loop;
  loop.motor = r.motor;
  loop.gains = out.gains;
  loop.period = 1.0 / r.sample_rate_hz;
  loop.vmax = out.voltage_limit_v;
  loop.step = out.step_a;

  if (r.duration_s > 0) {
    // Tolerate float noise: 10 ms at 12 kHz is 120 periods, not 121.
    const auto n = static_cast<std::size_t>(std::ceil(r.duration_s * r.sample_rate_hz - 1e-6)) + 1;
    out.samples = loop.run(std::clamp(n, std::size_t{2}, kMaxSamples));
  } else {
    // A few closed-loop time constants (L / Kp), longer until the response has settled,
    // but no longer than the slowest thing the loop can do could need.
    const double tau = r.motor.inductance_h / loop.gains.kp_v_per_a;
    const std::size_t longest = std::clamp(
        static_cast<std::size_t>(kSettleWindows * slowest_time_constant(loop, r.motor) * r.sample_rate_hz),
        kMinSamples, kMaxSamples);
    auto n = std::max(kMinSamples, static_cast<std::size_t>(kTimeConstants * tau * r.sample_rate_hz));
    for (n = std::min(n, longest);; n = std::min(2 * n, longest)) {
      out.samples = loop.run(n);
      const auto m = measure(out.samples, out.step_a, out.voltage_limit_v);
      if ((m.settling_time_s && std::abs(m.final_error_pct) < 1.0) || n == longest) break;
    }
  }
  out.metrics = measure(out.samples, out.step_a, out.voltage_limit_v);
  return out;
}

}  // namespace i20::profile
