// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/tune.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "profile/amp_limits.hpp"
#include "profile/error.hpp"

namespace i20::profile {
namespace {

// Below this many counts, rounding to an integer moves the gain by 5% or more.
constexpr double kCoarseCounts = 10.0;

double omega(double hz) {
  return 2.0 * std::numbers::pi * hz;
}

void require_positive(double value, const char* what) {
  if (!(value > 0) || !std::isfinite(value))
    throw TuneError(std::string(what) + " must be a positive number");
}

void check(const TuneRequest& r) {
  require_positive(r.motor.resistance_ohm, "the motor's phase resistance");
  require_positive(r.motor.inductance_h, "the motor's phase inductance");
  require_positive(r.max_current_a, "MAXCURRENT");
  require_positive(r.bus_voltage_v, "the bus voltage");
  require_positive(r.bandwidth_hz, "the current-loop bandwidth");
  require_positive(r.sample_rate_hz, "the loop sample rate");
  if (r.max_current_a > kAmpMaxCurrentA)
    throw TuneError("MAXCURRENT must not exceed the 8I20's " + limit_text(kAmpMaxCurrentA, "A"));
  const ReferenceTuning& ref = r.reference;
  require_positive(ref.motor.resistance_ohm, "the reference motor's resistance");
  require_positive(ref.motor.inductance_h, "the reference motor's inductance");
  require_positive(ref.max_current_a, "the reference MAXCURRENT");
  require_positive(ref.bus_voltage_v, "the reference bus voltage");
  require_positive(ref.bandwidth_hz, "the reference bandwidth");
  if (ref.kp <= 0 || ref.ki <= 0) throw TuneError("the reference gains must be positive");
}

using motor::ki_counts_per_unit;
using motor::kp_counts_per_unit;

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// Rounds to counts, keeps within [1, param max], and says so when it had to.
std::int64_t to_counts(double exact, const params::Param& p, std::vector<Finding>& warnings) {
  const double hi = static_cast<double>(p.max);
  const double lo = std::max<double>(1.0, static_cast<double>(p.min));
  if (exact > hi) {
    warnings.push_back(
        {Severity::Warning, p.name, "tune-clamp",
         "the model asks for " + number(exact) + ", clamped to the maximum " + std::to_string(p.max), ""});
    return p.max;
  }
  if (exact < lo - 0.5) {
    warnings.push_back({Severity::Warning, p.name, "tune-clamp",
                        "the model asks for " + number(exact) + ", raised to " + number(lo) +
                            " (zero would switch the term off)",
                        ""});
    return static_cast<std::int64_t>(lo);
  }
  if (exact < kCoarseCounts)
    warnings.push_back({Severity::Warning, p.name, "tune-resolution",
                        "the model asks for " + number(exact) +
                            "; at this size rounding to whole counts changes it by " +
                            number(100.0 * std::abs(std::round(exact) - exact) / exact) + "%",
                        ""});
  return std::max<std::int64_t>(static_cast<std::int64_t>(std::llround(exact)),
                                static_cast<std::int64_t>(lo));
}

}  // namespace

TuneResult tune(const TuneRequest& request, const params::ParamDb& db) {
  check(request);
  const ReferenceTuning& ref = request.reference;
  const double wc = omega(request.bandwidth_hz);
  TuneResult result;
  result.target = {request.motor.inductance_h * wc, request.motor.resistance_ohm * wc};
  result.kp_exact =
      result.target.kp_v_per_a * kp_counts_per_unit(request.max_current_a, request.bus_voltage_v, ref);
  result.ki_exact =
      result.target.ki_v_per_as * ki_counts_per_unit(request.max_current_a, request.bus_voltage_v, ref);
  result.kp = to_counts(result.kp_exact, db.get("NVKQP"), result.warnings);
  result.ki = to_counts(result.ki_exact, db.get("NVKQI"), result.warnings);
  result.achieved = physical_gains(result.kp, result.ki, request.max_current_a, request.bus_voltage_v, ref);
  if (wc / request.sample_rate_hz > kMaxDampedWcT)
    result.warnings.push_back({Severity::Warning, "bandwidth", "tune-bandwidth",
                               number(request.bandwidth_hz) + " Hz is above about " +
                                   number(kMaxDampedWcT * request.sample_rate_hz / (2.0 * std::numbers::pi)) +
                                   " Hz, where a loop sampled at " + number(request.sample_rate_hz / 1000.0) +
                                   " kHz with a one-period delay starts to overshoot",
                               ""});
  return result;
}

}  // namespace i20::profile
