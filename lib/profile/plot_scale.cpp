// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/plot_scale.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace i20::profile {

std::vector<double> nice_ticks(double max, int about) {
  if (!(max > 0)) return {0.0};
  const double rough = max / std::max(1, about);
  const double power = std::pow(10.0, std::floor(std::log10(rough)));
  double step = power;
  for (const double m : {1.0, 2.0, 5.0, 10.0})
    if (m * power >= rough) {
      step = m * power;
      break;
    }
  std::vector<double> ticks;
  for (int k = 0; k * step <= max * (1 + 1e-9); ++k) ticks.push_back(k * step);
  return ticks;
}

double current_axis_top(const StepResponse& response) {
  double peak = response.step_a;
  for (const auto& s : response.samples) peak = std::max(peak, s.current_a);
  return peak * 1.1;
}

std::string tick_label(double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", std::round(value * 1e6) / 1e6);
  return buf;
}

std::string metrics_summary(const StepResponse& response) {
  const StepMetrics& m = response.metrics;
  char buf[160];
  std::string text;
  std::snprintf(buf, sizeof buf, "step %.2f A: ", response.step_a);
  text += buf;
  if (m.rise_time_s) {
    std::snprintf(buf, sizeof buf, "rise %.3f ms", *m.rise_time_s * 1e3);
    text += buf;
  } else {
    text += "does not reach 90%";
  }
  std::snprintf(buf, sizeof buf, ", overshoot %.1f%%", m.overshoot_pct);
  text += buf;
  if (m.settling_time_s) {
    std::snprintf(buf, sizeof buf, ", settles (2%%) in %.3f ms", *m.settling_time_s * 1e3);
    text += buf;
  } else {
    text += ", not settled";
  }
  if (m.saturated) text += ", voltage-limited";
  return text;
}

}  // namespace i20::profile
