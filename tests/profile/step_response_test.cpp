// SPDX-License-Identifier: GPL-2.0-or-later
// The simulated current step: reaches the command, gets faster with bandwidth, and the
// plots are well-formed.
#include "profile/step_response.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "profile/svg_plot.hpp"
#include "profile/text_plot.hpp"
#include "test_util.hpp"

using namespace i20::profile;
using namespace i20::profile::testing;

namespace {

// A step with gains tuned for `bandwidth_hz` on a 1 ohm, 4 mH motor at 10 A, 300 V.
StepResponse tuned_step(double bandwidth_hz, double bus_v = 300.0, double step_a = 0) {
  TuneRequest r;
  r.motor = {1.0, 4e-3};
  r.max_current_a = 10.0;
  r.bus_voltage_v = bus_v;
  r.bandwidth_hz = bandwidth_hz;
  const auto t = tune(r, db());
  StepRequest s;
  s.motor = r.motor;
  s.max_current_a = r.max_current_a;
  s.bus_voltage_v = bus_v;
  s.kp = t.kp;
  s.ki = t.ki;
  s.step_a = step_a;
  return simulate_step(s);
}

// Minimal XML well-formedness: every tag closes in order, attributes quoted, one root.
bool well_formed(const std::string& xml, std::string& why) {
  std::vector<std::string> open;
  std::size_t pos = 0;
  int roots = 0;
  while ((pos = xml.find('<', pos)) != std::string::npos) {
    const auto end = xml.find('>', pos);
    if (end == std::string::npos) return (why = "unterminated tag"), false;
    const std::string tag = xml.substr(pos + 1, end - pos - 1);
    pos = end + 1;
    if (tag.starts_with("?")) continue;
    if (std::ranges::count(tag, '"') % 2 != 0) return (why = "unbalanced quotes in <" + tag + ">"), false;
    if (tag.starts_with("/")) {
      if (open.empty() || open.back() != tag.substr(1))
        return (why = "unexpected </" + tag.substr(1) + ">"), false;
      open.pop_back();
      continue;
    }
    const std::string name = tag.substr(0, tag.find_first_of(" \n/"));
    if (open.empty()) ++roots;
    if (!tag.ends_with("/")) open.push_back(name);
  }
  if (!open.empty()) return (why = "<" + open.back() + "> not closed"), false;
  if (roots != 1) return (why = "expected one root element"), false;
  // Text content must not hold a raw '&' that is not an entity.
  if (std::regex_search(xml, std::regex("&(?!amp;|lt;|gt;|quot;)"))) return (why = "raw &"), false;
  return true;
}

}  // namespace

TEST(TuneStep, SteadyStateReachesTheCommand) {
  for (const double bw : {100.0, 300.0, 500.0}) {
    const auto r = tuned_step(bw);
    EXPECT_NEAR(r.metrics.final_a, r.step_a, 0.01 * r.step_a) << bw;
    EXPECT_TRUE(r.metrics.settling_time_s) << bw;
    EXPECT_FALSE(r.metrics.saturated) << bw;
  }
}

TEST(TuneStep, RiseTimeShrinksWithBandwidth) {
  double previous = 1.0;
  for (const double bw : {100.0, 200.0, 400.0}) {
    const auto r = tuned_step(bw);
    ASSERT_TRUE(r.metrics.rise_time_s) << bw;
    EXPECT_LT(*r.metrics.rise_time_s, previous) << bw;
    previous = *r.metrics.rise_time_s;
  }
}

// Well below the loop rate the loop is first order: rise time 2.2 / wc.
TEST(TuneStep, LowBandwidthBehavesLikeTheContinuousDesign) {
  const double bw = 100.0;
  const auto r = tuned_step(bw);
  const double expected = 2.2 / (2 * 3.141592653589793 * bw);
  EXPECT_NEAR(*r.metrics.rise_time_s, expected, 0.15 * expected);
  EXPECT_LT(r.metrics.overshoot_pct, 1.0);
}

TEST(TuneStep, ReferenceTuningIsWellDamped) {
  const ReferenceTuning ref;
  StepRequest s;
  s.motor = ref.motor;
  s.max_current_a = ref.max_current_a;
  s.bus_voltage_v = ref.bus_voltage_v;
  s.kp = ref.kp;
  s.ki = ref.ki;
  const auto r = simulate_step(s);
  EXPECT_LT(r.metrics.overshoot_pct, 5.0);
  EXPECT_DOUBLE_EQ(r.step_a, 4.0);                    // half of MAXCURRENT by default
  EXPECT_NEAR(r.samples[1].t_s, 1.0 / 12000, 1e-12);  // sampled at the 12 kHz PWM rate
}

TEST(TuneStep, TooMuchBandwidthOvershoots) {
  EXPECT_GT(tuned_step(900.0).metrics.overshoot_pct, 10.0);
}

TEST(TuneStep, VoltageLimitSlowsALargeStepOnALowBus) {
  const auto free = tuned_step(300.0, 300.0, 10.0);
  const auto limited = tuned_step(300.0, 24.0, 10.0);
  EXPECT_FALSE(free.metrics.saturated);
  EXPECT_TRUE(limited.metrics.saturated);
  EXPECT_NEAR(limited.voltage_limit_v, 24.0 / std::sqrt(3.0), 1e-12);
  for (const auto& s : limited.samples) EXPECT_LE(std::abs(s.voltage_v), limited.voltage_limit_v + 1e-9);
  EXPECT_NEAR(limited.metrics.final_a, 10.0, 0.1);  // anti-windup: still gets there
}

TEST(TuneStep, MismatchedGainsStillSettleGivenTime) {
  // The manual's defaults on a fast, low-inductance motor on a low bus.
  StepRequest s;
  s.motor = {0.3, 0.6e-3};
  s.max_current_a = 10.0;
  s.bus_voltage_v = 48.0;
  s.kp = 50;
  s.ki = 150000;
  const auto r = simulate_step(s);
  EXPECT_NEAR(r.metrics.final_a, r.step_a, 0.01 * r.step_a);
}

TEST(TuneStep, FixedDurationGivesThatManySamples) {
  StepRequest s;
  s.motor = {1.0, 4e-3};
  s.max_current_a = 10;
  s.bus_voltage_v = 300;
  s.kp = 40;
  s.ki = 100000;
  s.duration_s = 0.01;
  EXPECT_EQ(simulate_step(s).samples.size(), 121u);
  s.kp = 0;
  EXPECT_THROW(simulate_step(s), TuneError);
}

TEST(TunePlot, SvgIsWellFormedAndAnnotated) {
  SvgOptions options;
  options.title = "X axis <400 W> & friends";
  const std::string svg = step_response_svg(tuned_step(600.0), options);
  std::string why;
  EXPECT_TRUE(well_formed(svg, why)) << why;
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("<svg xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos);
  EXPECT_NE(svg.find("X axis &lt;400 W&gt; &amp; friends"), std::string::npos);
  EXPECT_NE(svg.find("id=\"command\""), std::string::npos);
  EXPECT_NE(svg.find("id=\"response\""), std::string::npos);
  EXPECT_NE(svg.find("time (ms)"), std::string::npos);
  EXPECT_NE(svg.find("current (A)"), std::string::npos);
  EXPECT_NE(svg.find(">rise "), std::string::npos);
  EXPECT_NE(svg.find(">overshoot "), std::string::npos);
}

TEST(TunePlot, TextPlotIsCompact) {
  const auto r = tuned_step(300.0);
  TextPlotOptions options;
  options.width = 40;
  options.height = 6;
  const std::string text = step_response_text(r, options);
  EXPECT_EQ(std::ranges::count(text, '\n'), 6 + 3);
  EXPECT_NE(text.find("█"), std::string::npos);
  EXPECT_NE(text.find("rise"), std::string::npos);
  EXPECT_NE(text.find("ms"), std::string::npos);
  options.unicode = false;
  const std::string ascii = step_response_text(r, options);
  EXPECT_TRUE(std::ranges::all_of(ascii, [](char c) { return static_cast<unsigned char>(c) < 0x80; }));
  EXPECT_NE(ascii.find('#'), std::string::npos);
}

// The verdict `i20 tune` and `profile validate` share: a well-tuned loop passes, one that
// rings past kMaxAcceptedOvershootPct or never settles does not.
// The example: 0.6 ohm, 1.75 mH at 15 A on a 320 V bus, 2 kHz (wc*T = 1.05, far
// past the damped 0.35).
TuneRequest ringing_request() {
  TuneRequest r;
  r.motor = {0.6, 1.75e-3};
  r.max_current_a = 15.0;
  r.bus_voltage_v = 320.0;
  r.bandwidth_hz = 2000.0;
  return r;
}

TEST(TuneVerdict, AWellDampedLoopIsAccepted) {
  const auto verdict = judge_step(tuned_step(400.0));
  EXPECT_TRUE(verdict.acceptable) << verdict.reason;
  EXPECT_TRUE(verdict.reason.empty());
}

TEST(TuneVerdict, TooMuchBandwidthIsCalledUnstableAndSaysWhy) {
  const TuneRequest r = ringing_request();
  const auto t = tune(r, db());
  const auto step = simulate_step({r.motor, r.max_current_a, r.bus_voltage_v, t.kp, t.ki, {}, 0, 12000, 0});
  const auto verdict = judge_step(step);
  EXPECT_FALSE(verdict.acceptable);
  EXPECT_NE(verdict.reason.find("does not settle"), std::string::npos) << verdict.reason;
  EXPECT_EQ(judge_gains(r.motor, r.max_current_a, r.bus_voltage_v, t.kp, t.ki).reason, verdict.reason);
}

TEST(TuneVerdict, OvershootPastTheBoundIsNamed) {
  // 900 Hz rings (> 10%, TooMuchBandwidthOvershoots); find a bandwidth that settles but
  // overshoots past the accepted bound, and one just inside it.
  bool named = false;
  for (double hz = 700; hz <= 1500 && !named; hz += 50) {
    const auto step = tuned_step(hz);
    const auto verdict = judge_step(step);
    EXPECT_EQ(verdict.acceptable, step.metrics.settling_time_s.has_value() &&
                                      step.metrics.overshoot_pct <= kMaxAcceptedOvershootPct &&
                                      std::abs(step.metrics.final_error_pct) <= kMaxFinalErrorPct)
        << hz << " Hz";
    named = verdict.reason.find("overshoots") != std::string::npos;
  }
  EXPECT_TRUE(named) << "some bandwidth up to 1.5 kHz overshoots more than the bound";
}

TEST(TuneVerdict, ALoopThatNeverSettlesIsNotSimulatedForSeconds) {
  // It was simulated up to 200000 samples (16.7 s), which the plot's axis then showed.
  const TuneRequest r = ringing_request();
  const auto t = tune(r, db());
  const auto step = simulate_step({r.motor, r.max_current_a, r.bus_voltage_v, t.kp, t.ki, {}, 0, 12000, 0});
  // Ten of the slowest time constants: here the winding's L/R, 2.9 ms.
  EXPECT_LT(step.samples.back().t_s, 0.05);
  EXPECT_GT(step.samples.back().t_s, 0.02);
}
