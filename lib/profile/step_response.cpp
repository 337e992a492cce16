// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/step_response.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "profile/error.hpp"

namespace i20::profile {
namespace {

constexpr std::size_t kMinSamples = 24;
constexpr double kTimeConstants = 6.0;  // a first-order loop is within 0.25% by then
constexpr std::size_t kMaxSamples = 200000;
constexpr double kSettleBand = 0.02;

void require_positive(double value, const char* what) {
  if (!(value > 0) || !std::isfinite(value))
    throw TuneError(std::string(what) + " must be a positive number");
}

// Simulates `count` samples of the loop.
struct Loop {
  double a = 0, b = 0;  // i[k+1] = a i[k] + b v[k]
  double kp = 0, ki = 0, period = 0, vmax = 0, step = 0;

  std::vector<StepSample> run(std::size_t count) const {
    std::vector<StepSample> out;
    out.reserve(count);
    double i = 0, integral = 0, applied = 0;
    for (std::size_t k = 0; k < count; ++k) {
      out.push_back({static_cast<double>(k) * period, step, i, applied});
      const double e = step - i;
      const double wanted = kp * e + integral;
      const double v = std::clamp(wanted, -vmax, vmax);
      // Integrate only while unsaturated, or when the error pulls out of saturation.
      if (v == wanted || (e > 0) != (wanted > 0)) integral += ki * period * e;
      i = a * i + b * applied;  // the plant sees last period's output
      applied = v;
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

}  // namespace

StepResponse simulate_step(const StepRequest& r) {
  require_positive(r.motor.resistance_ohm, "the motor's phase resistance");
  require_positive(r.motor.inductance_h, "the motor's phase inductance");
  require_positive(r.max_current_a, "MAXCURRENT");
  require_positive(r.bus_voltage_v, "the bus voltage");
  require_positive(r.sample_rate_hz, "the loop sample rate");
  if (r.kp <= 0 || r.ki < 0) throw TuneError("the gains to simulate must be positive");
  StepResponse out;
  out.step_a = r.step_a > 0 ? r.step_a : 0.5 * r.max_current_a;
  out.voltage_limit_v = r.bus_voltage_v / std::sqrt(3.0);
  out.gains = physical_gains(r.kp, r.ki, r.max_current_a, r.bus_voltage_v, r.reference);

  Loop loop;
  loop.period = 1.0 / r.sample_rate_hz;
  loop.a = std::exp(-r.motor.resistance_ohm * loop.period / r.motor.inductance_h);
  loop.b = (1.0 - loop.a) / r.motor.resistance_ohm;
  loop.kp = out.gains.kp_v_per_a;
  loop.ki = out.gains.ki_v_per_as;
  loop.vmax = out.voltage_limit_v;
  loop.step = out.step_a;

  if (r.duration_s > 0) {
    // Tolerate float noise: 10 ms at 12 kHz is 120 periods, not 121.
    const auto n = static_cast<std::size_t>(std::ceil(r.duration_s * r.sample_rate_hz - 1e-6)) + 1;
    out.samples = loop.run(std::clamp(n, std::size_t{2}, kMaxSamples));
  } else {
    // A few closed-loop time constants (L / Kp), longer until the response has settled.
    const double tau = r.motor.inductance_h / loop.kp;
    auto n = std::max(kMinSamples, static_cast<std::size_t>(kTimeConstants * tau * r.sample_rate_hz));
    for (n = std::min(n, kMaxSamples);; n = std::min(2 * n, kMaxSamples)) {
      out.samples = loop.run(n);
      const auto m = measure(out.samples, out.step_a, out.voltage_limit_v);
      if ((m.settling_time_s && std::abs(m.final_error_pct) < 1.0) || n == kMaxSamples) break;
    }
  }
  out.metrics = measure(out.samples, out.step_a, out.voltage_limit_v);
  return out;
}

}  // namespace i20::profile
