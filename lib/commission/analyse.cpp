// SPDX-License-Identifier: GPL-2.0-or-later
#include "commission/analyse.hpp"

#include <algorithm>

#include "commission/encoder_analysis.hpp"
#include "commission/format.hpp"
#include "commission/hall_analysis.hpp"
#include "commission/sweep.hpp"
#include "error/error.hpp"

namespace i20::commission {

namespace {

constexpr std::size_t kMinimumSamples = 16;
// One whole electrical turn each way after settling: every Hall state and every angle
// through the cogging ripple is seen at least once in each direction.
constexpr double kMinimumTravelTurns = 1.0;

void check_options(const AnalysisOptions& options) {
  if (options.pole_pairs && *options.pole_pairs < 1) {
    throw UsageError("pole pairs must be 1 or more, not " + std::to_string(*options.pole_pairs));
  }
  if (options.counts_per_turn && *options.counts_per_turn < 1) {
    throw UsageError("counts per turn must be 1 or more, not " + std::to_string(*options.counts_per_turn));
  }
  if (!(options.settle_turns >= 0)) throw UsageError("the settle travel must be 0 or more turns");
}

}  // namespace

bool CommutationResult::has(ProblemKind kind) const {
  return std::any_of(problems.begin(), problems.end(), [&](const Problem& p) { return p.kind == kind; });
}

CommutationResult analyse(std::span<const Sample> samples, const AnalysisOptions& options) {
  check_options(options);
  CommutationResult result;
  if (samples.size() < kMinimumSamples) {
    result.problems.push_back(
        {ProblemKind::NotEnoughSamples, std::to_string(samples.size()) + " samples: too few to analyse"});
    return result;
  }
  const Sweep sweep = read_sweep(samples, options.settle_turns);
  const double forward = sweep.steady_travel(1), backward = sweep.steady_travel(-1);
  if (forward < kMinimumTravelTurns || backward < kMinimumTravelTurns) {
    result.problems.push_back({ProblemKind::SweepTooShort,
                               "the command swept " + fixed(forward, 2) + " electrical turns forward and " +
                                   fixed(backward, 2) + " back after settling; the analysis needs " +
                                   fixed(kMinimumTravelTurns, 0) + " each way (plus " +
                                   fixed(options.settle_turns, 2) + " to settle)"});
    return result;
  }
  const auto encoder = analyse_encoder(samples, sweep, options, result);
  const bool rotor_followed = !result.has(ProblemKind::NoMotion) &&
                              !result.has(ProblemKind::MoveDisagreesWithCommand) &&
                              !result.has(ProblemKind::InconsistentCountsPerElectricalTurn);
  if (!options.hall_sensors_expected) return result;
  if (!rotor_followed) {
    if (!result.has(ProblemKind::NoMotion)) {
      result.notes.push_back("the Hall sensors were not judged: the rotor did not follow the command");
    }
    return result;
  }
  analyse_hall(samples, sweep, encoder, options, result);
  return result;
}

}  // namespace i20::commission
