// SPDX-License-Identifier: GPL-2.0-or-later
// The profile commands' writes (`i20 profile apply` on one card or a fleet, `undo`, and
// `validate` against cards, which is apply's dry run): one use case, ProfileApply, judged
// by every rule that needs no card when it is made and run by the one write transaction
// (lib/ops/apply_run.hpp) on whatever the front end names.
#pragma once

#include <functional>
#include <vector>

#include "ops/apply_run.hpp"
#include "ops/fleet.hpp"

namespace i20::ops {

// Told the plan once it is known, before the first write (a front end shows it).
using PlanShown = std::function<void(const profile::Plan&)>;

// Made from the request before any link opens: the constructor judges the job
// (make_apply_job: read-only, known address, range, guard, the card's fixed limits) and
// throws SafetyError / ValueError with nothing sent; the rules that compare with the card
// are the transaction's, before its first write. Every run is that job, so a dry run
// (validate, apply --dry-run) plans exactly what a write runs.
class ProfileApply {
 public:
  explicit ProfileApply(const ApplyRequest& request);

  const ApplyJob& job() const { return job_; }

  // One run per target, in their order: one card directly, several as the fleet
  // (concurrent across lines, lib/ops/fleet.hpp).
  std::vector<TargetRun> run_on(const std::vector<Endpoint>& targets,
                                const FleetActivity& activity = {}) const;
  // One target it opens and closes.
  TargetRun run_on(const Endpoint& target, const Activity& activity = {},
                   const PlanShown& plan_shown = {}) const;
  // A card already open (undo reads the card's identity before it picks the backup).
  TargetRun run_on(Amp& amp, const Activity& activity = {}, const PlanShown& plan_shown = {}) const;

 private:
  ApplyJob with_plan_shown(const PlanShown& plan_shown) const;

  ApplyJob job_;
};

}  // namespace i20::ops
