// One profile, many cards: every independent line gets its own thread (with its own link,
// database copy and card client), so a slow or dead card delays nobody and one target
// failing never changes what happens on another.
#pragma once

#include <vector>

#include "apply_run.hpp"
#include "target_spec.hpp"

namespace i20::cli {

struct FleetOptions {
  // Redraw one status line per target on stderr while the threads run (for a terminal).
  bool progress = false;
};

// Runs in the order given within a line (targets sharing a link_key), concurrently across
// lines. Returns one run per target, in the order of `targets`.
std::vector<TargetRun> run_fleet(const std::vector<TargetSpec>& targets, const ApplyJob& job,
                                 const FleetOptions& options);

}  // namespace i20::cli
