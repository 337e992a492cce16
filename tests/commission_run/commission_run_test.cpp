// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 commission` as a use case on the virtual axis (a virtual 7I92T servo card over
// loopback UDP, a virtual 8I20 driving a simulated motor): seeded random motors where every
// value found equals the simulator's truth or the report says why it could not tell, and
// each abort ending with zero current and an honest report.
#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "ops/outcome.hpp"
#include "virtual_axis.hpp"

using namespace i20;
using namespace i20::test;
using namespace std::chrono_literals;

namespace {

struct Run {
  ops::CommissionPlan plan;
  ops::CommissionReport report;
};

Run commission(VirtualAxis& axis, const ops::CommissionOptions& options) {
  ops::Session session(axis.session_options());
  Run run;
  run.plan = ops::prepare_commission(session, options);
  run.report = ops::run_commission(session, run.plan, options);
  return run;
}

std::string describe(const ops::CommissionReport& r) {
  std::string s = std::string(ops::stop_reason_name(r.stop)) + ": " + r.message;
  if (r.result)
    for (const auto& p : r.result->problems) s += "\n  problem: " + p.message;
  for (const auto& n : r.notes) s += "\n  note: " + n;
  if (r.check) s += "\n  check: " + r.check->how;
  return s;
}

double angle_diff_deg(double a, double b) {
  return std::abs(std::remainder(a - b, 360.0));
}

// Every value equals the truth, or a problem says why it is absent.
void expect_truth(const VirtualAxis& axis, const ops::CommissionReport& r) {
  const auto& p = axis.params();
  ASSERT_TRUE(r.result) << describe(r);
  ASSERT_TRUE(r.bldc);
  const auto& b = *r.bldc;
  if (b.poles) {
    EXPECT_EQ(*b.poles, 2 * p.pole_pairs) << describe(r);
  } else {
    EXPECT_FALSE(b.missing.empty()) << describe(r);
  }
  if (b.scale) {
    EXPECT_EQ(*b.scale, p.encoder->direction * p.encoder->counts_per_turn) << describe(r);
  }
  const auto pattern = true_pattern(p);
  if (b.pattern) {
    EXPECT_EQ(b.pattern, pattern) << describe(r);
  } else {
    EXPECT_FALSE(r.result->problems.empty() && r.notes.empty()) << describe(r);
  }
  ASSERT_TRUE(r.result->index_electrical_angle_deg) << describe(r);
  EXPECT_LT(angle_diff_deg(r.result->index_electrical_angle_deg->value, true_index_electrical_deg(p)), 3.0)
      << describe(r);
}

TEST(CommissionRun, FindsAndChecksTheServo) {
  VirtualAxis axis(MotorSpec{});
  const auto run = commission(axis, quick_options());
  const auto& r = run.report;
  EXPECT_EQ(r.stop, ops::StopReason::Completed) << describe(r);
  EXPECT_EQ(r.outcome(), ops::Outcome::Done);
  expect_truth(axis, r);
  ASSERT_TRUE(r.check);
  EXPECT_TRUE(r.check->passed) << describe(r);
  EXPECT_EQ(r.encoder_instance, 0u);
  EXPECT_EQ(r.hall_pins, (std::vector<std::string>{"gpio.010.in", "gpio.011.in", "gpio.012.in"}));
  EXPECT_TRUE(r.current_zeroed);
  EXPECT_EQ(axis.qsetpoint(), 0.0);
  EXPECT_LT(r.doit.worst(), 40ms);
}

}  // namespace
