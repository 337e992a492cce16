// SPDX-License-Identifier: GPL-2.0-or-later
#include "commission/encoder_analysis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "commission/circular.hpp"
#include "commission/format.hpp"

namespace i20::commission {

namespace {

// ODrive's threshold for "the encoder moved" (encoder.cpp: more than 8 counts), per turn.
constexpr double kStillCountsPerTurn = 8.0;
// ODrive fails its offset calibration when counts/turn differ from the expected by > 2%;
// forward and backward must agree as well. 3% leaves room for cogging over short sweeps.
constexpr double kCountsPerTurnTolerance = 0.03;
// A rotor that strays more than a quarter electrical turn from a straight line has slipped.
constexpr double kMaxStrayTurns = 0.25;
// Beyond 45 electrical degrees of lag the rotor is close to slipping.
constexpr double kMaxLagTurns = 0.125;

struct LineFit {
  double slope = 0;         // counts per electrical turn
  double slope_error = 0;   // standard error
  double max_residual = 0;  // counts
  double count_change = 0;  // summed over the runs
};

// Count against command over the steady samples of one direction; each run has its own
// intercept (the lag may differ between runs), one slope for all.
LineFit fit_direction(std::span<const Sample> samples, const Sweep& sweep, int direction) {
  double sxx = 0, sxy = 0;
  std::size_t n = 0;
  LineFit fit;
  std::vector<std::pair<double, double>> means;  // per run: mean command, mean count
  for (const SweepRun& run : sweep.runs) {
    if (run.direction != direction) continue;
    double mx = 0, my = 0;
    const auto count = static_cast<double>(run.end - run.steady_begin);
    for (std::size_t i = run.steady_begin; i < run.end; ++i) {
      mx += sweep.command[i];
      my += static_cast<double>(samples[i].encoder_count);
    }
    mx /= count;
    my /= count;
    means.emplace_back(mx, my);
    for (std::size_t i = run.steady_begin; i < run.end; ++i) {
      const double dx = sweep.command[i] - mx;
      sxx += dx * dx;
      sxy += dx * (static_cast<double>(samples[i].encoder_count) - my);
    }
    n += run.end - run.steady_begin;
    fit.count_change +=
        static_cast<double>(samples[run.end - 1].encoder_count - samples[run.steady_begin].encoder_count);
  }
  if (sxx <= 0) return fit;
  fit.slope = sxy / sxx;
  double sse = 0;
  std::size_t r = 0;
  for (const SweepRun& run : sweep.runs) {
    if (run.direction != direction) continue;
    const auto [mx, my] = means[r++];
    for (std::size_t i = run.steady_begin; i < run.end; ++i) {
      const double residual =
          static_cast<double>(samples[i].encoder_count) - my - fit.slope * (sweep.command[i] - mx);
      sse += residual * residual;
      fit.max_residual = std::max(fit.max_residual, std::abs(residual));
    }
  }
  if (n > 2) fit.slope_error = std::sqrt(sse / static_cast<double>(n - 2) / sxx);
  return fit;
}

// The Hall sensors show motion when at least two of them changed (a lone noisy sensor on a
// stalled rotor does not count).
bool halls_moved(std::span<const Sample> samples, const Sweep& sweep) {
  std::array<std::size_t, 3> changes{};
  for (const SweepRun& run : sweep.runs) {
    for (std::size_t i = run.steady_begin + 1; i < run.end; ++i) {
      const auto changed = samples[i].hall_state ^ samples[i - 1].hall_state;
      for (int sensor = 1; sensor <= 3; ++sensor) {
        if (changed & hall_bit(sensor)) ++changes[static_cast<std::size_t>(sensor - 1)];
      }
    }
  }
  return std::count_if(changes.begin(), changes.end(), [](std::size_t n) { return n >= 2; }) >= 2;
}

std::vector<std::int64_t> index_latches(std::span<const Sample> samples) {
  std::vector<std::int64_t> latches;
  for (const Sample& s : samples) {
    if (s.index_seen) latches.push_back(s.latched_count);
  }
  return latches;
}

// Distinct index marks: latches within `tolerance` counts of each other are one mark.
std::vector<double> index_marks(std::vector<std::int64_t> latches, double tolerance) {
  std::sort(latches.begin(), latches.end());
  std::vector<double> marks;
  std::vector<std::size_t> members;
  for (std::int64_t latch : latches) {
    const auto value = static_cast<double>(latch);
    if (!marks.empty() && value - marks.back() <= tolerance) {
      marks.back() = (marks.back() * static_cast<double>(members.back()) + value) /
                     static_cast<double>(members.back() + 1);
      ++members.back();
    } else {
      marks.push_back(value);
      members.push_back(1);
    }
  }
  return marks;
}

// Counts per turn from index marks a turn apart: every gap between neighbouring marks must
// be the same.
std::optional<Finding<double>> counts_per_turn_from_index(const std::vector<double>& marks) {
  if (marks.size() < 2) return std::nullopt;
  double low = marks[1] - marks[0], high = low, sum = 0;
  for (std::size_t i = 1; i < marks.size(); ++i) {
    const double gap = marks[i] - marks[i - 1];
    low = std::min(low, gap);
    high = std::max(high, gap);
    sum += gap;
  }
  if (high - low > 3.0) return std::nullopt;
  const double mean = sum / static_cast<double>(marks.size() - 1);
  return Finding<double>{
      std::round(mean), (high - low) / 2.0,
      "the distance between " + std::to_string(marks.size()) + " index marks a turn apart"};
}

// One index mark and a given counts per turn: had the encoder travelled a given turn past the
// mark either way, the index would have latched there too. False (a problem added) when it
// did and did not; a note when the given turn, alone deciding the pole pairs, went unchecked.
bool one_mark_agrees(std::span<const Sample> samples, double mark, double turn, double tolerance,
                     bool pole_pairs_given, CommutationResult& result) {
  const auto [low, high] =
      std::minmax_element(samples.begin(), samples.end(),
                          [](const auto& a, const auto& b) { return a.encoder_count < b.encoder_count; });
  const auto lowest = static_cast<double>(low->encoder_count);
  const auto highest = static_cast<double>(high->encoder_count);
  if (mark + turn < highest - tolerance || mark - turn > lowest + tolerance) {
    result.problems.push_back(
        {ProblemKind::IndexInconsistent,
         "the index latched at one mark while the encoder covered " + fixed(highest - lowest, 0) +
             " counts: a turn of " + fixed(turn, 0) +
             " counts would have latched it again, so the counts per turn are wrong (a turn is more than " +
             fixed(std::max(highest - mark, mark - lowest), 0) + " counts), or the index is missing pulses"});
    return false;
  }
  if (!pole_pairs_given)
    result.notes.push_back("the index passed once: the given " + fixed(turn, 0) +
                           " counts per turn, which set the pole pairs, could not be checked against it");
  return true;
}

// The index contradicts the counts per turn given: what was derived from them (the pole
// pairs, unless given too) must not reach bldc's settings.
void forget_scale(const AnalysisOptions& options, CommutationResult& result) {
  result.counts_per_turn.reset();
  if (!options.pole_pairs) result.pole_pairs.reset();
}

struct Scale {
  double counts_per_electrical_turn = 0;  // what the offset is computed with
  bool exact = false;                     // from an exact counts per turn and pole pairs
};

// Decides the pole pairs and counts per turn; returns the counts per electrical turn to use,
// or nullopt when a problem stops the offset.
std::optional<Scale> decide_scale(const AnalysisOptions& options, const Finding<double>& measured,
                                  const std::optional<Finding<double>>& from_index,
                                  CommutationResult& result) {
  const double cpet = measured.value;
  const auto relative = [&](double expected) { return std::abs(cpet / expected - 1.0); };
  if (options.pole_pairs && options.counts_per_turn) {
    const int pp = *options.pole_pairs;
    const auto cpr = static_cast<double>(*options.counts_per_turn);
    const double expected = cpr / pp;
    if (relative(expected) > kCountsPerTurnTolerance) {
      result.problems.push_back({ProblemKind::CountsPerTurnMismatch,
                                 "the rotor moved " + fixed(cpet, 1) + " counts per electrical turn, but " +
                                     std::to_string(*options.counts_per_turn) + " counts per turn over " +
                                     std::to_string(pp) + " pole pairs make " + fixed(expected, 1) +
                                     ": the pole pairs or counts per turn are wrong, or the rotor slipped"});
      return std::nullopt;
    }
    result.pole_pairs =
        Finding<int>{pp, 0, "given; the sweep agrees (" + fixed(cpet, 1) + " counts per electrical turn)"};
    result.counts_per_turn = Finding<double>{cpr, 0, "given"};
    return Scale{expected, true};
  }
  if (options.pole_pairs) {
    const int pp = *options.pole_pairs;
    result.pole_pairs = Finding<int>{pp, 0, "given"};
    const double estimate = cpet * pp;
    const double estimate_error = measured.uncertainty * pp;
    if (from_index) {
      if (std::abs(from_index->value - estimate) >
          std::max(estimate_error, kCountsPerTurnTolerance * estimate)) {
        result.problems.push_back(
            {ProblemKind::IndexInconsistent, "index marks " + fixed(from_index->value, 0) +
                                                 " counts apart, but the sweep makes " + fixed(estimate, 0) +
                                                 " counts per turn with " + std::to_string(pp) +
                                                 " pole pairs: a noisy index, or the pole pairs are wrong"});
        return std::nullopt;
      }
      result.counts_per_turn = from_index;
      return Scale{from_index->value / pp, from_index->uncertainty <= 0.5};
    }
    result.counts_per_turn =
        Finding<double>{estimate, estimate_error, "counts per electrical turn x the given pole pairs"};
    if (estimate_error >= 0.5) {
      result.problems.push_back({ProblemKind::CountsPerTurnInexact,
                                 "counts per turn estimated as " + fixed(estimate, 1) + " +/- " +
                                     fixed(estimate_error, 1) +
                                     ": bldc's scale needs the exact number (encoder lines x 4), give it"});
    }
    return Scale{cpet, false};
  }
  std::optional<Finding<double>> cpr;
  if (options.counts_per_turn) {
    cpr = Finding<double>{static_cast<double>(*options.counts_per_turn), 0, "given"};
  } else if (from_index) {
    cpr = from_index;
  }
  if (!cpr) {
    result.problems.push_back(
        {ProblemKind::NeedPolePairsOrCounts,
         "the index did not pass twice, so the counts per turn are unknown, and the pole "
         "pairs need them or the pole count: give either (a motor with more pole pairs than "
         "half the search's electrical turns needs one)"});
    return Scale{cpet, false};
  }
  result.counts_per_turn = cpr;
  const double ratio = cpr->value / cpet;
  const double ratio_error = ratio * (measured.uncertainty / cpet + cpr->uncertainty / cpr->value);
  const long pp = std::lround(ratio);
  if (pp < 1 || std::abs(ratio - static_cast<double>(pp)) + ratio_error >= 0.5 ||
      std::abs(ratio / static_cast<double>(pp) - 1.0) > kCountsPerTurnTolerance) {
    result.problems.push_back(
        {ProblemKind::PolePairsNotInteger,
         "counts per turn / counts per electrical turn = " + fixed(ratio, 3) + " +/- " +
             fixed(ratio_error, 3) +
             ", not a whole number of pole pairs: the counts per turn are wrong, or the "
             "rotor slipped"});
    return std::nullopt;
  }
  result.pole_pairs =
      Finding<int>{static_cast<int>(pp), 0,
                   "counts per turn (" + cpr->how + ") / counts per electrical turn = " + fixed(ratio, 3)};
  return Scale{cpr->value / static_cast<double>(pp), cpr->uncertainty <= 0.5};
}

struct DirectionMean {
  double mean_turns = 0;
  double error_turns = 0;    // one standard error
  double sample_spread = 0;  // how far single samples stray from the mean (circular deviation)
};

// The mean of (command - encoder angle) over one direction, from one mean per electrical
// turn of travel (cogging repeats with the position, so single samples are not independent).
DirectionMean mean_over_direction(std::span<const Sample> samples, const Sweep& sweep, int direction,
                                  const RotorAngleFromEncoder& encoder) {
  std::map<std::pair<std::size_t, long>, CircularMean> blocks;
  CircularMean all;
  for (std::size_t r = 0; r < sweep.runs.size(); ++r) {
    const SweepRun& run = sweep.runs[r];
    if (run.direction != direction) continue;
    for (std::size_t i = run.steady_begin; i < run.end; ++i) {
      const double difference = sweep.command[i] - (encoder.rotor_turns(samples[i].encoder_count) -
                                                    encoder.angle_at_reference_turns);
      const long block = static_cast<long>(std::floor(std::abs(sweep.command[i] - run.steady_start_turns)));
      blocks[{r, block}].add(difference);
      all.add(difference);
    }
  }
  CircularMean of_blocks;
  for (const auto& [key, block] : blocks) {
    if (block.count() * 2 >= all.count() / std::max<std::size_t>(blocks.size(), 1))
      of_blocks.add(block.mean_turns());
  }
  DirectionMean mean;
  mean.mean_turns = of_blocks.empty() ? all.mean_turns() : of_blocks.mean_turns();
  mean.error_turns = of_blocks.count() >= 3
                         ? of_blocks.deviation_turns() / std::sqrt(static_cast<double>(of_blocks.count()))
                         : all.deviation_turns();
  mean.sample_spread = all.deviation_turns();
  return mean;
}

void report_offset(const RotorAngleFromEncoder& encoder, double cpet, int direction,
                   CommutationResult& result) {
  const double at_index = wrap_turns(encoder.angle_at_reference_turns);
  const double uncertainty_deg = encoder.uncertainty_turns * 360.0;
  result.index_electrical_angle_deg =
      Finding<double>{at_index * 360.0, uncertainty_deg,
                      "mean of (command - encoder angle) over both sweeps, which cancels the friction lag"};
  // bldc: rotor-angle = frac((raw - index - encoder-offset) * pole pairs / scale); zero at
  // raw - index = encoder-offset, i.e. where the encoder angle has come back to 0.
  const double to_zero = wrap_turns(-at_index * direction);
  auto counts = static_cast<std::int64_t>(std::llround(to_zero * cpet));
  if (static_cast<double>(counts) >= std::round(cpet)) counts = 0;
  result.encoder_offset_counts = Finding<std::int64_t>{
      counts, uncertainty_deg / 360.0 * cpet,
      "counts from the index to electrical zero in the counting direction (bldc encoder-offset)"};
  result.encoder_offset_deg = Finding<double>{to_zero * 360.0, uncertainty_deg,
                                              "electrical degrees from the index to electrical zero"};
}

// Did the rotor follow the command both ways, steadily? Names what went wrong if not.
bool followed_command(std::span<const Sample> samples, const Sweep& sweep, const LineFit& forward,
                      const LineFit& backward, CommutationResult& result) {
  const bool forward_moved = std::abs(forward.count_change) >= kStillCountsPerTurn * sweep.steady_travel(1);
  const bool backward_moved =
      std::abs(backward.count_change) >= kStillCountsPerTurn * sweep.steady_travel(-1);
  if (!forward_moved && !backward_moved) {
    if (halls_moved(samples, sweep)) {
      result.problems.push_back({ProblemKind::EncoderSilent,
                                 "the Hall sensors changed but the encoder did not count: is the encoder "
                                 "connected and powered?"});
    } else {
      result.problems.push_back(
          {ProblemKind::NoMotion,
           "no motion: is the brake released, the motor connected? (" + fixed(forward.count_change, 0) +
               " and " + fixed(backward.count_change, 0) + " counts over the sweeps, Hall sensors still)"});
    }
    return false;
  }
  if (!forward_moved || !backward_moved || (forward.slope > 0) != (backward.slope > 0)) {
    result.problems.push_back(
        {ProblemKind::MoveDisagreesWithCommand, "the rotor did not follow the command both ways (" +
                                                    fixed(forward.count_change, 0) + " counts forward, " +
                                                    fixed(backward.count_change, 0) +
                                                    " back): a load, a brake, or too little current"});
    return false;
  }
  const double stray = std::max(forward.max_residual / std::abs(forward.slope),
                                backward.max_residual / std::abs(backward.slope));
  if (stray > kMaxStrayTurns) {
    result.problems.push_back({ProblemKind::MoveDisagreesWithCommand,
                               "the rotor strayed " + fixed(stray * 360.0, 0) +
                                   " electrical degrees from the command's steady line: it slipped or stuck "
                                   "(too little current, a load, or cogging stronger than the current)"});
    return false;
  }
  return true;
}

// Counts per electrical turn from the two slopes, or nullopt (and a problem) when they disagree.
std::optional<Finding<double>> counts_per_electrical_turn(const Sweep& sweep, const LineFit& forward,
                                                          const LineFit& backward,
                                                          CommutationResult& result) {
  const double magnitude = (std::abs(forward.slope) + std::abs(backward.slope)) / 2.0;
  const double disagreement = std::abs(std::abs(forward.slope) - std::abs(backward.slope));
  if (disagreement / magnitude > kCountsPerTurnTolerance) {
    result.problems.push_back({ProblemKind::InconsistentCountsPerElectricalTurn,
                               "forward " + fixed(std::abs(forward.slope), 1) + " and backward " +
                                   fixed(std::abs(backward.slope), 1) +
                                   " counts per electrical turn disagree: the rotor slipped or the encoder "
                                   "missed counts"});
    return std::nullopt;
  }
  // Cogging ripple is not random: it can tilt a fitted line by about twice its amplitude over
  // the travel, which the regression's standard error does not show.
  const double travel_forward = sweep.steady_travel(1), travel_backward = sweep.steady_travel(-1);
  const double quantisation = 2.0 / std::min(travel_forward, travel_backward);
  const double ripple =
      2.0 * std::max(forward.max_residual / travel_forward, backward.max_residual / travel_backward);
  const double uncertainty = disagreement / 2.0 +
                             3.0 * std::hypot(forward.slope_error, backward.slope_error) / 2.0 +
                             quantisation + ripple;
  return Finding<double>{magnitude, uncertainty,
                         "slope of count against command, fitted on each sweep and averaged"};
}

// The farthest any steady sample is from the reference, in electrical turns.
double farthest_turns(std::span<const Sample> samples, const Sweep& sweep,
                      const RotorAngleFromEncoder& encoder) {
  double far = 0;
  for (const SweepRun& run : sweep.runs) {
    for (std::size_t i = run.steady_begin; i < run.end; ++i) {
      far = std::max(far, std::abs(static_cast<double>(samples[i].encoder_count) - encoder.reference_count));
    }
  }
  return far / std::abs(encoder.signed_counts_per_electrical_turn);
}

// The electrical angle at the reference count, with the lag it cancels.
void calibrate_angle(std::span<const Sample> samples, const Sweep& sweep, const Scale& scale,
                     const Finding<double>& measured, RotorAngleFromEncoder& encoder,
                     CommutationResult& result) {
  const DirectionMean forward = mean_over_direction(samples, sweep, 1, encoder);
  const DirectionMean backward = mean_over_direction(samples, sweep, -1, encoder);
  encoder.angle_at_reference_turns = circular_midpoint(forward.mean_turns, backward.mean_turns);
  const double spread = std::hypot(forward.error_turns, backward.error_turns);
  const double lag = wrap_signed(forward.mean_turns - backward.mean_turns) / 2.0;
  result.friction_lag_deg = Finding<double>{lag * 360.0, 3.0 * spread * 180.0,
                                            "half the gap between the forward and backward means"};
  if (std::abs(lag) > kMaxLagTurns) {
    result.notes.push_back("the rotor trailed the command by " + fixed(lag * 360.0, 0) +
                           " electrical degrees: raise the sweep current or slow the sweep");
  }
  // Without an exact scale, the error in counts per electrical turn grows with the distance
  // from the reference.
  const double scale_drift = scale.exact ? 0.0
                                         : farthest_turns(samples, sweep, encoder) * measured.uncertainty /
                                               scale.counts_per_electrical_turn;
  // The rotor's jitter (cogging, vibration) shakes the play between rotor and encoder, which
  // then cancels between the directions only on average: a tenth of it is added (found on
  // synthetic motors shaken harder than the tests' ranges).
  encoder.jitter_turns = std::max(forward.sample_spread, backward.sample_spread);
  encoder.uncertainty_turns =
      3.0 * spread / 2.0 + 1.0 / scale.counts_per_electrical_turn + scale_drift + 0.1 * encoder.jitter_turns;
}

}  // namespace

std::optional<RotorAngleFromEncoder> analyse_encoder(std::span<const Sample> samples, const Sweep& sweep,
                                                     const AnalysisOptions& options,
                                                     CommutationResult& result) {
  const LineFit forward = fit_direction(samples, sweep, 1);
  const LineFit backward = fit_direction(samples, sweep, -1);
  if (!followed_command(samples, sweep, forward, backward, result)) return std::nullopt;
  const auto measured = counts_per_electrical_turn(sweep, forward, backward, result);
  if (!measured) return std::nullopt;
  result.counts_per_electrical_turn = measured;
  const int direction = forward.slope > 0 ? 1 : -1;
  result.encoder_direction = Finding<int>{
      direction, 0,
      direction > 0 ? "counts rose as the commanded angle rose (both sweeps agree)"
                    : "counts fell as the commanded angle rose (both sweeps agree): bldc scale negative"};

  // The index: latches at one mark (both ways) or marks a turn apart.
  const auto marks = index_marks(index_latches(samples), 3.0 + 0.01 * measured->value);
  const auto from_index = counts_per_turn_from_index(marks);
  const auto scale = decide_scale(options, *measured, from_index, result);
  if (!scale) return std::nullopt;
  if (from_index && options.counts_per_turn &&
      std::abs(from_index->value - static_cast<double>(*options.counts_per_turn)) >
          2.0 + from_index->uncertainty) {
    result.problems.push_back(
        {ProblemKind::IndexInconsistent, "index marks " + fixed(from_index->value, 0) +
                                             " counts apart, but a turn is " +
                                             std::to_string(*options.counts_per_turn) +
                                             " counts: a noisy index, or the counts per turn are wrong"});
    forget_scale(options, result);
    return std::nullopt;
  }
  if (marks.size() == 1 && options.counts_per_turn &&
      !one_mark_agrees(samples, marks.front(), static_cast<double>(*options.counts_per_turn),
                       3.0 + 0.01 * measured->value, options.pole_pairs.has_value(), result)) {
    forget_scale(options, result);
    return std::nullopt;
  }
  if (marks.size() > 1 && !from_index) {
    result.problems.push_back({ProblemKind::IndexInconsistent,
                               "the index latched at marks that are not a whole turn apart: a noisy index?"});
    return std::nullopt;
  }
  if (marks.empty()) {
    result.problems.push_back({ProblemKind::NoIndex,
                               "no index latched during the sweep: sweep more than one mechanical turn (pole "
                               "pairs + 1 electrical turns) each way, or check the index wiring"});
  }

  RotorAngleFromEncoder encoder;
  encoder.signed_counts_per_electrical_turn = direction * scale->counts_per_electrical_turn;
  encoder.reference_count = marks.empty() ? 0.0 : marks.front();
  calibrate_angle(samples, sweep, *scale, *measured, encoder, result);
  if (!marks.empty()) report_offset(encoder, scale->counts_per_electrical_turn, direction, result);
  return encoder;
}

}  // namespace i20::commission
