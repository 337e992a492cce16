// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/hal_file.hpp"

#include "error/error.hpp"
#include "linuxcnc/hal_lint.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

namespace L = linuxcnc;

std::string generate_hal_file(const L::HalPlan& plan) {
  L::check_plan(plan);
  std::string text = L::generate_hal(plan, {timing::kHalPortRunDelay, timing::kHalFaultWatchDelay});
  const L::LintOptions strict{plan.max_current, plan.pattern};
  const auto findings = L::lint(L::read_hal(text, "generated"), strict);
  if (!findings.empty())
    throw Error("internal error: the generated HAL fails its own lint: " + L::to_string(findings[0]));
  return text;
}

}  // namespace i20::ops
