// SPDX-License-Identifier: GPL-2.0-or-later
#include "commission/hall_analysis.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <map>
#include <vector>

#include "commission/circular.hpp"
#include "commission/format.hpp"

namespace i20::commission {

namespace {

constexpr double kDeg = 1.0 / 360.0;  // one electrical degree in turns
// A sample this close to a sensor's expected edge may fairly read either way; more when the
// rotor angle is less certain or the rotor jitters (see edge_margin()).
constexpr double kEdgeMargin = 15.0 * kDeg;
// More wrong readings than this, away from the edges, make a sensor noisy.
constexpr double kNoisyFraction = 0.005;
// A state seen in less than this share of a sector's worth of samples is a glitch.
constexpr double kGlitchShare = 0.2;
// Crossings further than this from their edge's median are glitches.
constexpr double kCrossingOutlier = 8.0 * kDeg;
// States further than this from bldc's sector centres could be either of two patterns.
constexpr double kAmbiguousOffset = 25.0 * kDeg;
constexpr double kWarnOffset = 10.0 * kDeg;

struct Point {
  double angle;  // rotor electrical angle, turns
  HallCode code;
  int direction;  // of the sweep run
  std::size_t run;
};

std::vector<Point> points_of(std::span<const Sample> samples, const Sweep& sweep,
                             const std::optional<RotorAngleFromEncoder>& encoder) {
  std::vector<Point> points;
  for (std::size_t r = 0; r < sweep.runs.size(); ++r) {
    const SweepRun& run = sweep.runs[r];
    for (std::size_t i = run.steady_begin; i < run.end; ++i) {
      const double angle = encoder ? encoder->rotor_turns(samples[i].encoder_count) : sweep.command[i];
      points.push_back(
          {wrap_turns(angle), static_cast<HallCode>(samples[i].hall_state & 7), run.direction, r});
    }
  }
  return points;
}

std::string sensor_name(int sensor) {
  return "hall" + std::to_string(sensor);
}

// How many bins a turn is cut into to locate a sensor's high half-turn: as fine as 2 degrees,
// but never finer than two encoder counts, so every bin holds readings and the parts of the
// turn a coarse encoder reads more often do not weigh more.
std::size_t bins_for(double counts_per_electrical_turn) {
  constexpr std::size_t kFinest = 180;
  if (counts_per_electrical_turn <= 0) return kFinest;  // angles from the command: continuous
  return std::clamp<std::size_t>(static_cast<std::size_t>(counts_per_electrical_turn / 2.0), 12, kFinest);
}

double edge_margin(const std::optional<RotorAngleFromEncoder>& encoder) {
  if (!encoder) return kEdgeMargin;
  return kEdgeMargin + encoder->uncertainty_turns + 3.0 * encoder->jitter_turns;
}

HallSensorFinding judge_sensor(const std::vector<Point>& points, int sensor, std::size_t bin_count,
                               double margin) {
  HallSensorFinding finding;
  finding.sensor = sensor;
  const HallCode bit = hall_bit(sensor);
  const auto highs = static_cast<std::size_t>(
      std::count_if(points.begin(), points.end(), [&](const Point& p) { return (p.code & bit) != 0; }));
  if (highs == points.size()) {
    finding.condition = SensorCondition::StuckHigh;
    finding.how = sensor_name(sensor) +
                  " read high all through the sweep: stuck high, or missing (an open input "
                  "with a pull-up reads high)";
    return finding;
  }
  if (highs == 0) {
    finding.condition = SensorCondition::StuckLow;
    finding.how = sensor_name(sensor) + " read low all through the sweep: stuck low, shorted, or unpowered";
    return finding;
  }
  // A sensor is high for half an electrical turn: compare each sample with that half turn,
  // found for each direction on its own (against the command the lag shifts it each way).
  // Angles are binned first so a part of the turn swept twice does not pull the centre.
  // [direction][bin][high?]
  std::array<std::vector<std::array<std::size_t, 2>>, 2> bins{
      std::vector<std::array<std::size_t, 2>>(bin_count), std::vector<std::array<std::size_t, 2>>(bin_count)};
  for (const Point& p : points) {
    const auto bin =
        std::min(bin_count - 1, static_cast<std::size_t>(p.angle * static_cast<double>(bin_count)));
    ++bins[p.direction > 0 ? 0 : 1][bin][(p.code & bit) ? 1 : 0];
  }
  std::array<CircularMean, 2> high_by_direction;
  for (std::size_t d = 0; d < 2; ++d) {
    for (std::size_t b = 0; b < bin_count; ++b) {
      const std::size_t total = bins[d][b][0] + bins[d][b][1];
      if (total == 0) continue;
      high_by_direction[d].add((static_cast<double>(b) + 0.5) / static_cast<double>(bin_count),
                               static_cast<double>(bins[d][b][1]) / static_cast<double>(total));
    }
  }
  const double centre = high_by_direction[0].empty()   ? high_by_direction[1].mean_turns()
                        : high_by_direction[1].empty() ? high_by_direction[0].mean_turns()
                                                       : circular_midpoint(high_by_direction[0].mean_turns(),
                                                                           high_by_direction[1].mean_turns());
  std::size_t judged = 0, wrong = 0;
  for (const Point& p : points) {
    const CircularMean& own = high_by_direction[p.direction > 0 ? 0 : 1];
    if (own.empty()) continue;
    const double from_centre = std::abs(wrap_signed(p.angle - own.mean_turns()));
    if (std::abs(from_centre - 0.25) < margin) continue;
    ++judged;
    const bool expected_high = from_centre < 0.25;
    if (expected_high != ((p.code & bit) != 0)) ++wrong;
  }
  finding.high_centre_deg = centre * 360.0;
  finding.wrong_fraction = judged ? static_cast<double>(wrong) / static_cast<double>(judged) : 0.0;
  if (finding.wrong_fraction > kNoisyFraction) {
    finding.condition = SensorCondition::Noisy;
    finding.how = sensor_name(sensor) + " noisy: " + fixed(finding.wrong_fraction * 100.0, 1) +
                  "% of its readings away from its edges contradict its half-turn pattern";
  } else {
    finding.how = sensor_name(sensor) + " high for half a turn centred on " +
                  fixed(finding.high_centre_deg, 1) + " electrical degrees";
  }
  return finding;
}

std::string codes_text(const std::vector<HallCode>& codes) {
  std::string text;
  for (HallCode c : codes) text += (text.empty() ? "" : ", ") + hall_code_text(c);
  return text;
}

struct StateStats {
  std::size_t samples = 0;
  CircularMean angle;
};

// The mean of one edge's crossings in one direction, glitches left out.
struct CrossingMean {
  double mean = 0;
  double error = 0;  // standard error, turns
  std::size_t count = 0;
};

CrossingMean robust_mean(const std::vector<double>& crossings) {
  CrossingMean out;
  if (crossings.empty()) return out;
  // The median (taken around the circular mean) is not pulled by a few glitches; the mean of
  // the crossings near it is the estimate.
  CircularMean first;
  for (double c : crossings) first.add(c);
  std::vector<double> around;
  for (double c : crossings) around.push_back(wrap_signed(c - first.mean_turns()));
  std::nth_element(around.begin(), around.begin() + static_cast<std::ptrdiff_t>(around.size() / 2),
                   around.end());
  const double median = first.mean_turns() + around[around.size() / 2];
  CircularMean kept;
  for (double c : crossings) {
    if (std::abs(wrap_signed(c - median)) <= kCrossingOutlier) kept.add(c);
  }
  if (kept.empty()) return out;
  out.mean = kept.mean_turns();
  out.count = kept.count();
  out.error = kept.deviation_turns() / std::sqrt(static_cast<double>(kept.count()));
  return out;
}

class HallAnalysis {
 public:
  HallAnalysis(std::vector<Point> points, const std::optional<RotorAngleFromEncoder>& encoder,
               const AnalysisOptions& options, CommutationResult& result)
      : points_(std::move(points)),
        from_encoder_(encoder.has_value()),
        bin_count_(bins_for(encoder ? std::abs(encoder->signed_counts_per_electrical_turn) : 0.0)),
        margin_(edge_margin(encoder)),
        options_(options),
        result_(result) {}

  void run() {
    judge_sensors();
    if (!find_six_states()) return;
    if (!order_states()) return;
    if (!place_edges()) return;
    name_sequence();
  }

 private:
  void problem(ProblemKind kind, std::string message) {
    result_.problems.push_back({kind, std::move(message)});
  }
  std::string reference() const {
    return from_encoder_ ? "the encoder's rotor angle" : "the commanded angle";
  }

  void judge_sensors() {
    std::vector<std::string> stuck;
    for (int sensor = 1; sensor <= 3; ++sensor) {
      HallSensorFinding finding = judge_sensor(points_, sensor, bin_count_, margin_);
      if (finding.condition == SensorCondition::StuckHigh || finding.condition == SensorCondition::StuckLow) {
        stuck.push_back(finding.how);
      } else if (finding.condition == SensorCondition::Noisy) {
        result_.notes.push_back(finding.how);
      }
      result_.hall.sensors.push_back(std::move(finding));
    }
    if (stuck.size() == 3) {
      problem(ProblemKind::HallStuck,
              "no Hall sensor changed during the sweep: are the Hall sensors connected and "
              "powered?");
    } else {
      for (std::string& line : stuck) problem(ProblemKind::HallStuck, std::move(line));
    }
  }

  bool find_six_states() {
    for (const Point& p : points_) {
      stats_[p.code].samples++;
      stats_[p.code].angle.add(p.angle);
    }
    const double sector_share = static_cast<double>(points_.size()) / 6.0;
    std::vector<HallCode> seen, glitches;
    for (HallCode code = 0; code < 8; ++code) {
      if (stats_[code].samples == 0) continue;
      if (static_cast<double>(stats_[code].samples) >= kGlitchShare * sector_share) {
        seen.push_back(code);
        significant_[code] = true;
      } else {
        glitches.push_back(code);
      }
    }
    if (seen.size() < 6) {
      problem(ProblemKind::FewerThanSixHallStates,
              "only " + std::to_string(seen.size()) + " Hall states seen (" + codes_text(seen) +
                  "); three working sensors show six each electrical turn");
      return false;
    }
    if (seen.size() > 6) {
      problem(ProblemKind::MoreThanSixHallStates, std::to_string(seen.size()) + " Hall states seen (" +
                                                      codes_text(seen) +
                                                      "); three sensors 60 or 120 degrees apart show six: a "
                                                      "noisy sensor, or sensors placed otherwise");
      return false;
    }
    std::vector<HallCode> unused;
    for (HallCode code = 0; code < 8; ++code) {
      if (!significant_[code]) unused.push_back(code);
    }
    if ((unused[0] ^ unused[1]) != 7) {
      problem(ProblemKind::HallUnusedNotComplementary,
              "the unused Hall states " + codes_text(unused) +
                  " are not complementary: the sensors are not 60 or 120 electrical degrees apart");
      return false;
    }
    unused_low_ = unused[0];
    if (!glitches.empty()) {
      result_.notes.push_back("Hall state(s) " + codes_text(glitches) + " seen briefly (glitches), ignored");
    }
    return true;
  }

  bool order_states() {
    for (HallCode code = 0; code < 8; ++code) {
      if (significant_[code]) order_.push_back(code);
    }
    std::sort(order_.begin(), order_.end(), [&](HallCode a, HallCode b) {
      return stats_[a].angle.mean_turns() < stats_[b].angle.mean_turns();
    });
    for (std::size_t k = 0; k < 6; ++k) {
      const HallCode a = order_[k], b = order_[(k + 1) % 6];
      if (std::popcount(static_cast<unsigned>(a ^ b)) != 1) {
        problem(
            ProblemKind::HallOrderInconsistent,
            "in increasing electrical angle the Hall states run " + codes_text(order_) +
                ": neighbours differ in more than one sensor, so the sensors do not switch one at a time");
        return false;
      }
    }
    return true;
  }

  // crossings[k][0] forward, [1] backward: edge k lies between order_[k] and order_[k+1].
  using Crossings = std::array<std::array<std::vector<double>, 2>, 6>;

  Crossings collect_crossings() const {
    Crossings crossings;
    std::map<HallCode, std::size_t> position;
    for (std::size_t k = 0; k < 6; ++k) position[order_[k]] = k;
    std::optional<HallCode> stable;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const Point& p = points_[i];
      if (i > 0 && p.run != points_[i - 1].run) stable.reset();
      if (!significant_[p.code]) continue;
      // A new state must hold for the next sample too: a one-sample flip is a glitch.
      const bool holds =
          i + 1 < points_.size() && points_[i + 1].run == p.run && points_[i + 1].code == p.code;
      if (stable && *stable != p.code) {
        if (!holds) continue;
        const std::size_t a = position[*stable], b = position[p.code];
        const double at = circular_midpoint(points_[i - 1].angle, p.angle);
        const std::size_t side = p.direction > 0 ? 0 : 1;
        if ((a + 1) % 6 == b) {
          crossings[a][side].push_back(at);
        } else if ((b + 1) % 6 == a) {
          crossings[b][side].push_back(at);
        }
      }
      stable = p.code;
    }
    return crossings;
  }

  // How far the rotor moved between two samples at most: a crossing is known to half of it.
  double widest_step() const {
    double widest = 0;
    for (std::size_t i = 1; i < points_.size(); ++i) {
      if (points_[i].run == points_[i - 1].run) {
        widest = std::max(widest, std::abs(wrap_signed(points_[i].angle - points_[i - 1].angle)));
      }
    }
    return widest;
  }

  // Edge k from its crossings both ways (their midpoint cancels the sensor's hysteresis).
  std::optional<HallEdgeAngle> edge_from(const Crossings& crossings, std::size_t k, double step) {
    const CrossingMean forward = robust_mean(crossings[k][0]);
    const CrossingMean backward = robust_mean(crossings[k][1]);
    HallEdgeAngle found;
    found.before = order_[k];
    found.after = order_[(k + 1) % 6];
    if (forward.count == 0 && backward.count == 0) {
      problem(ProblemKind::HallEdgeMissing, "the Hall edge " + hall_code_text(found.before) + "/" +
                                                hall_code_text(found.after) + " was never crossed");
      return std::nullopt;
    }
    double angle = 0, error = 0;
    std::string how;
    if (forward.count && backward.count) {
      angle = circular_midpoint(forward.mean, backward.mean);
      found.hysteresis_deg = wrap_signed(forward.mean - backward.mean) / 2.0 * 360.0;
      error = 3.0 * std::hypot(forward.error, backward.error) / 2.0 + step / 2.0;
      how = "mean of " + std::to_string(forward.count) + " forward and " + std::to_string(backward.count) +
            " backward crossings against " + reference();
    } else {
      const CrossingMean& one = forward.count ? forward : backward;
      angle = one.mean;
      error = 3.0 * one.error + step / 2.0 + 5.0 * kDeg;  // hysteresis not cancelled
      how = "mean of " + std::to_string(one.count) + " crossings one way only against " + reference() +
            " (hysteresis not cancelled)";
    }
    found.angle_deg = Finding<double>{angle * 360.0, error * 360.0, how};
    return found;
  }

  bool place_edges() {
    const Crossings crossings = collect_crossings();
    const double step = widest_step();
    for (std::size_t k = 0; k < 6; ++k) {
      auto edge = edge_from(crossings, k, step);
      if (!edge) return false;
      result_.hall.edges.push_back(std::move(*edge));
    }
    const auto& edges = result_.hall.edges;
    for (std::size_t k = 0; k < 6; ++k) {
      const HallEdgeAngle& entry = edges[(k + 5) % 6];
      const HallEdgeAngle& exit = edges[k];
      const double width = wrap_turns((exit.angle_deg.value - entry.angle_deg.value) / 360.0);
      HallStateAngle state;
      state.code = order_[k];
      state.centre_deg =
          Finding<double>{wrap_turns(entry.angle_deg.value / 360.0 + width / 2.0) * 360.0,
                          std::hypot(entry.angle_deg.uncertainty, exit.angle_deg.uncertainty) / 2.0,
                          "half way between its two edges"};
      if (width < 30.0 * kDeg || width > 90.0 * kDeg) {
        result_.notes.push_back("Hall state " + hall_code_text(state.code) + " spans " +
                                fixed(width * 360.0, 0) + " electrical degrees, not 60");
      }
      result_.hall.states.push_back(std::move(state));
    }
    return true;
  }

  void name_sequence() {
    auto& hall = result_.hall;
    CircularMean sixfold;  // the states' common offset from multiples of 60 degrees
    double worst_error = 0;
    for (const HallStateAngle& s : hall.states) {
      sixfold.add(6.0 * s.centre_deg.value / 360.0);
      worst_error = std::max(worst_error, s.centre_deg.uncertainty);
    }
    const double offset = wrap_signed(sixfold.mean_turns()) / 6.0;
    hall.offset_from_bldc_sectors_deg = Finding<double>{
        offset * 360.0, worst_error, "mean offset of the six state centres from multiples of 60 degrees"};
    if (std::abs(offset) > kAmbiguousOffset) {
      problem(ProblemKind::HallBetweenSectors,
              "the Hall states sit " + fixed(offset * 360.0, 0) +
                  " electrical degrees from bldc's sector centres, about half way between two patterns: "
                  "either would commutate about 30 degrees off");
      return;
    }
    if (std::abs(offset) > kWarnOffset) {
      result_.notes.push_back(
          "the Hall states sit " + fixed(offset * 360.0, 0) +
          " electrical degrees from bldc's sector centres: trapezoidal (h) commutation and qh's "
          "first estimate will be that far off");
    }
    HallSequence sequence;
    std::array<bool, 6> taken{};
    for (HallStateAngle& s : hall.states) {
      const long k = std::lround((s.centre_deg.value / 360.0 - offset) * 6.0);
      s.bldc_sector = static_cast<int>(((k % 6) + 6) % 6);
      if (taken[static_cast<std::size_t>(s.bldc_sector)]) {
        problem(ProblemKind::HallOrderInconsistent,
                "two Hall states fall in one bldc sector: uneven sensor spacing");
        return;
      }
      taken[static_cast<std::size_t>(s.bldc_sector)] = true;
      sequence.code_at_sector[static_cast<std::size_t>(s.bldc_sector)] = s.code;
    }
    const auto row = find_hall_row(sequence);
    if (!row) {  // cannot happen for a Gray 6-cycle with a complementary unused pair
      problem(ProblemKind::HallOrderInconsistent, "the Hall sequence is none of bldc's 48 patterns");
      return;
    }
    const HallTableRow& table_row = hall_table()[*row];
    std::string listing;
    for (std::size_t k = 0; k < 6; ++k) {
      listing += (k ? ", " : "") + hall_code_text(sequence.code_at_sector[k]) + "->" + std::to_string(60 * k);
    }
    hall.sequence =
        Finding<HallSequence>{sequence, 0, "each state's centre rounded to bldc's sectors: " + listing};
    hall.table_row = row;
    const bool is_120 = table_row.layout == HallLayout::Deg120;
    if (!is_120) {
      for (int sensor = 1; sensor <= 3; ++sensor) {
        const HallCode flipped = unused_low_ ^ hall_bit(sensor);
        if (flipped == 0 || flipped == 7) hall.middle_sensor_of_60 = sensor;
      }
    }
    hall.layout = Finding<HallLayout>{
        table_row.layout, 0,
        is_120 ? "states 000 and 111 unused: sensors 120 electrical degrees apart"
               : "states " + hall_code_text(unused_low_) + " and " + hall_code_text(unused_low_ ^ 7) +
                     " unused: sensors 60 electrical degrees apart, " +
                     sensor_name(hall.middle_sensor_of_60) + " in the middle (or 120 apart with " +
                     sensor_name(hall.middle_sensor_of_60) + " inverted)"};
    if (options_.expected_hall_layout && *options_.expected_hall_layout != table_row.layout) {
      problem(ProblemKind::HallLayoutUnexpected, std::string("expected a ") + (is_120 ? "60" : "120") +
                                                     " degree Hall layout, found " + (is_120 ? "120" : "60") +
                                                     ": " + hall.layout->how);
    }
    hall.rewiring_to_25 = rewiring_to_pattern_25(sequence);
    if (table_row.bldc_pattern) {
      hall.bldc_pattern =
          Finding<int>{*table_row.bldc_pattern, 0,
                       "the Hall map is " + listing + ", row " + std::to_string(*table_row.bldc_pattern) +
                           " of bldc(9)'s pattern table"};
    } else {
      problem(ProblemKind::PatternNumberUnknown, "the Hall map is " + listing +
                                                     "; it is not in bldc's pattern table: feed "
                                                     "bldc " +
                                                     hall.rewiring_to_25->describe() + " and use pattern 25");
    }
  }

  std::vector<Point> points_;
  bool from_encoder_;
  std::size_t bin_count_;
  double margin_;
  const AnalysisOptions& options_;
  CommutationResult& result_;
  std::array<StateStats, 8> stats_{};
  std::array<bool, 8> significant_{};
  std::vector<HallCode> order_;
  HallCode unused_low_ = 0;
};

}  // namespace

void analyse_hall(std::span<const Sample> samples, const Sweep& sweep,
                  const std::optional<RotorAngleFromEncoder>& encoder, const AnalysisOptions& options,
                  CommutationResult& result) {
  HallAnalysis(points_of(samples, sweep, encoder), encoder, options, result).run();
}

}  // namespace i20::commission
