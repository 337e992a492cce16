// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/profile_apply.hpp"

namespace i20::ops {

ProfileApply::ProfileApply(const ApplyRequest& request) : job_(make_apply_job(request)) {}

std::vector<TargetRun> ProfileApply::run_on(const std::vector<Endpoint>& targets,
                                            const FleetActivity& activity) const {
  if (targets.size() == 1) {
    const Activity one =
        activity ? Activity([&](const std::string& what) { activity(0, what); }) : Activity();
    return {run_apply(targets.front(), job_, one)};
  }
  return run_fleet(targets, job_, activity);
}

TargetRun ProfileApply::run_on(const Endpoint& target, const Activity& activity,
                               const PlanShown& plan_shown) const {
  return run_apply(target, with_plan_shown(plan_shown), activity);
}

TargetRun ProfileApply::run_on(Amp& amp, const Activity& activity, const PlanShown& plan_shown) const {
  return run_apply_on(amp, with_plan_shown(plan_shown), activity);
}

// The request's own hook stays unless the run names one (the job is a few pointers and
// options: copying it leaves the judged job as it was for the next run).
ApplyJob ProfileApply::with_plan_shown(const PlanShown& plan_shown) const {
  if (!plan_shown) return job_;
  auto job = job_;
  job.transaction.on_plan = plan_shown;
  return job;
}

}  // namespace i20::ops
