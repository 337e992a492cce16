// SPDX-License-Identifier: GPL-2.0-or-later
// The moving half of `i20 commission`: align, sweep, analyse, check; every way out zeroes
// the current and stops the port before the report is written.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "commission/analyse.hpp"
#include "commission/format.hpp"
#include "commission/hall_table.hpp"
#include "device/errors.hpp"
#include "eth/errors.hpp"
#include "link/link.hpp"
#include "linuxcnc/hal_file.hpp"
#include "motor/amp_gains.hpp"
#include "ops/commission/commission.hpp"
#include "ops/commission/commission_motion.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

using commission::fixed;
using namespace commission_detail;

namespace {

// The command travel over which the first forward turn tells the scale, and a stall.
constexpr double kScaleTurns = 1.0;
// Fewer counts than this over that turn: the encoder did not move.
constexpr std::int64_t kStallCounts = 4;
// Given figures within this share of the first turn's measure are trusted for the follow
// check (the first turn measures within a few percent; a wrong figure is off by a pole pair).
constexpr double kGivenScaleAgreement = 0.2;
// The check: how far each push should get (its waits: timing.hpp).
constexpr double kCheckEnoughTurns = 0.5;
constexpr double kCheckMinTurns = 0.25;
// Hall codes off the pattern's sector tolerated in the check (edges blur by hysteresis).
constexpr double kHallMismatchLimit = 0.02;
// tune-axis: a period whose held angle gave under this share of the command's torque is one
// the loop did not keep (an angle 37 electrical degrees stale); more than this share of such
// periods and the record is not fitted.
constexpr double kLeastTorqueShare = 0.8;
constexpr double kMostWeakShare = 0.02;

double wrap_turns(double t) {  // to [-0.5, 0.5)
  return t - std::floor(t + 0.5);
}

// The identification's record of what the 8I20 held: the ANGLE it took last (electrical
// turns) and where the rotor was when the period began.
struct HeldAngle {
  double angle = 0;
  double rotor = 0;
  bool taken = true;  // this period's command reached the 8I20
};

// The share of a command's torque the 8I20 gave over one period: its current lies along the
// ANGLE it holds while the rotor turns on from `from` to `to`, so the torque is the command
// times the mean cosine of the angle between them.
double share_in_effect(double held, double from, double to) {
  const double a = 2 * std::numbers::pi * (held - from), b = 2 * std::numbers::pi * (held - to);
  if (std::abs(b - a) < 1e-9) return std::cos(a);
  return (std::sin(a) - std::sin(b)) / (a - b);
}

std::size_t encoder_index(const eth::DriveLoop& loop, unsigned instance) {
  const auto& encoders = loop.feedback().encoders;
  for (std::size_t e = 0; e < encoders.size(); ++e)
    if (encoders[e].instance == instance) return e;
  throw UsageError(std::string("--encoder ") + std::to_string(instance) + ": the card has " +
                   std::to_string(encoders.size()) + " encoder(s), 0.." +
                   std::to_string(encoders.size() - 1));
}

std::vector<std::size_t> named_inputs(const eth::DriveLoop& loop, const std::vector<std::string>& names) {
  const auto& inputs = loop.feedback().inputs;
  std::vector<std::size_t> out;
  for (const auto& name : names) {
    const auto it =
        std::find_if(inputs.begin(), inputs.end(), [&](const auto& in) { return in.hal_pin == name; });
    if (it == inputs.end()) {
      std::string known;
      for (const auto& in : inputs) {
        if (!known.empty()) known += ", ";
        known += in.hal_pin;
      }
      throw UsageError("--halls: " + name + " is not an input of this card (" + known + ")");
    }
    out.push_back(static_cast<std::size_t>(it - inputs.begin()));
  }
  return out;
}

// --- the sweep ---------------------------------------------------------------------------

class Procedure {
 public:
  Procedure(Motion& motion, const CommissionPlan& plan, const CommissionOptions& options,
            const CommissionProgress& progress, CommissionReport& report)
      : m_(motion), plan_(plan), options_(options), progress_(progress), report_(report) {}

  void commission();
  void check_only(const BldcSetup& setup);
  void identify_axis(const BldcSetup& setup);
  void correct_for_current_loop(mechanics::Mechanics& found);

 private:
  void say(const std::string& phase) {
    if (progress_) progress_(phase);
  }
  void align(double at_turns);
  void sweep_to(double from, double to, bool learn_scale);
  double sweep_forward();
  void learn_scale(std::size_t sweep_start);
  std::vector<std::size_t> choose_halls(std::size_t from);
  std::vector<commission::Sample> samples(std::size_t encoder, const std::vector<std::size_t>& halls) const;
  commission::HallCode hall_code(const Tick& tick, const std::vector<std::size_t>& halls) const;

  struct Rotor {  // what the check believes about the rotor
    Scale scale;
    std::int64_t zero_count = 0;  // a count where the electrical angle is 0
    std::optional<commission::HallSequence> halls_sequence;
    std::vector<std::size_t> halls;
    double angle(std::int64_t count) const {
      return scale.direction * static_cast<double>(count - zero_count) / scale.counts_per_electrical_turn;
    }
  };
  std::optional<Rotor> find_rotor(const BldcSetup& setup);
  ClosedLoopCheck closed_loop(const Rotor& rotor);
  double push(const Rotor& rotor, int sign, ClosedLoopCheck& check);
  double hold_error(const Rotor& rotor, double at_turns);
  bool torque_in_effect(const std::vector<HeldAngle>& held);

  Motion& m_;
  const CommissionPlan& plan_;
  const CommissionOptions& options_;
  const CommissionProgress& progress_;
  CommissionReport& report_;
  double command_ = 0;
};

void Procedure::align(double at_turns) {
  say(std::string("aligning: ramping to ") + fixed(plan_.current_a, 2) + " A at electrical angle 0");
  command_ = at_turns;
  const double dt = m_.loop().period().count() / 1000.0;
  for (double t = 0; t < plan_.align_s; t += dt)
    m_.hold(plan_.current_a * std::min(1.0, plan_.ramp_s > 0 ? t / plan_.ramp_s : 1.0), command_);
}

void Procedure::sweep_to(double from, double to, bool learn) {
  const double dt = m_.loop().period().count() / 1000.0;
  const double step = (to > from ? 1 : -1) * plan_.turns_per_s * dt;
  const std::size_t start = m_.ticks().size();
  bool learned = !learn;
  for (command_ = from; (to - command_) * (to > from ? 1 : -1) > 1e-9;) {
    command_ = to > from ? std::min(to, command_ + step) : std::max(to, command_ + step);
    m_.hold(plan_.current_a, command_);
    if (!learned && std::abs(command_ - from) >= kScaleTurns) {
      learn_scale(start);
      learned = true;
    }
  }
}

// Forward the planned turns, and on (up to the plan's search) until the index has passed
// as often as the plan needs: once for the offset, twice (a mechanical turn apart) when the
// exact counts per turn must come from the index.
double Procedure::sweep_forward() {
  sweep_to(0.0, plan_.sweep_turns, true);
  const auto e = m_.scale()->encoder;
  auto latches = [&] {
    return std::count_if(m_.ticks().begin(), m_.ticks().end(),
                         [&](const Tick& t) { return t.index_latch[e].has_value(); });
  };
  double end = plan_.sweep_turns;
  while (latches() < plan_.index_passes && end < plan_.search_turns) {
    say("still sweeping forward: waiting for the index");
    sweep_to(end, end + 1.0, false);
    end += 1.0;
  }
  return end;
}

// After the first forward turn: which encoder moved, which way, how many counts per turn;
// or a stall.
void Procedure::learn_scale(std::size_t sweep_start) {
  const auto& ticks = m_.ticks();
  const auto& first = ticks.at(sweep_start == 0 ? 0 : sweep_start - 1);
  const auto& now = ticks.back();
  std::size_t e = 0;
  if (options_.encoder) {
    e = encoder_index(m_.loop(), *options_.encoder);
  } else {
    for (std::size_t k = 1; k < now.counts.size(); ++k)
      if (std::abs(now.counts[k] - first.counts[k]) > std::abs(now.counts[e] - first.counts[e])) e = k;
  }
  const std::int64_t moved = now.counts[e] - first.counts[e];
  if (std::abs(moved) < kStallCounts) {
    const auto changes = m_.input_changes(sweep_start, ticks.size());
    const bool inputs_moved = std::any_of(changes.begin(), changes.end(), [](unsigned c) { return c > 0; });
    const std::string encoder =
        std::string("encoder ") + std::to_string(m_.loop().feedback().encoders[e].instance);
    if (inputs_moved)
      throw Abort(StopReason::Stall,
                  "inputs changed but " + encoder +
                      " did not count through a full electrical turn "
                      "of command: is the encoder connected, and is it that one (--encoder)?");
    throw Abort(StopReason::Stall, "the rotor did not move through a full electrical turn of command at " +
                                       fixed(plan_.current_a, 2) + " A (" + encoder +
                                       " and every input still): is "
                                       "the brake released, the motor connected, the current enough?");
  }
  Scale scale{.encoder = e,
              .direction = moved > 0 ? 1 : -1,
              .counts_per_electrical_turn = std::abs(static_cast<double>(moved)) / kScaleTurns};
  // Given figures make the follow check exact, but only when the rotor agrees with them: a
  // wrong --poles or --counts-per-rev would make the check see a slip that is not there
  // (the analysis names the mismatch instead).
  if (options_.pole_pairs && options_.counts_per_turn) {
    const double given = static_cast<double>(*options_.counts_per_turn) / *options_.pole_pairs;
    if (std::abs(given / scale.counts_per_electrical_turn - 1.0) < kGivenScaleAgreement)
      scale.counts_per_electrical_turn = given;
  }
  report_.encoder_instance = m_.loop().feedback().encoders[e].instance;
  m_.set_scale(scale, true);
}

// The three inputs that changed during the sweep (or the ones named).
std::vector<std::size_t> Procedure::choose_halls(std::size_t from) {
  if (options_.no_halls) return {};
  if (!options_.halls.empty()) return named_inputs(m_.loop(), options_.halls);
  const auto changes = m_.input_changes(from, m_.ticks().size());
  std::vector<std::size_t> changed;
  for (std::size_t k = 0; k < changes.size(); ++k)
    if (changes[k] >= plan_.sweep_turns) changed.push_back(k);  // a Hall changes ~4x per turn there and back
  const auto& inputs = m_.loop().feedback().inputs;
  std::string names;
  for (auto k : changed) {
    if (!names.empty()) names += ", ";
    names += inputs[k].hal_pin;
  }
  if (changed.size() == 3) return changed;
  if (changed.empty())
    report_.notes.push_back(
        "no input changed during the sweep: the motor has no Hall sensors on this card's inputs "
        "(or name them with --halls)");
  else
    report_.notes.push_back(
        std::to_string(changed.size()) + " input(s) changed during the sweep (" + names +
        "), not three: name the Hall inputs with --halls (a sensor may be stuck or missing)");
  return {};
}

commission::HallCode Procedure::hall_code(const Tick& tick, const std::vector<std::size_t>& halls) const {
  commission::HallCode code = 0;
  for (std::size_t h = 0; h < halls.size(); ++h)
    if (m_.input_bit(tick, halls[h]))
      code = static_cast<commission::HallCode>(code | commission::hall_bit(int(h) + 1));
  return code;
}

std::vector<commission::Sample> Procedure::samples(std::size_t encoder,
                                                   const std::vector<std::size_t>& halls) const {
  std::vector<commission::Sample> out;
  for (const auto& tick : m_.ticks()) {
    commission::Sample s;
    s.t_s = tick.t_s;
    s.commanded_electrical_turns = tick.command_turns;
    s.encoder_count = tick.counts[encoder];
    s.hall_state = hall_code(tick, halls);
    if (tick.index_latch[encoder]) {
      s.index_seen = true;
      s.latched_count = *tick.index_latch[encoder];
    }
    out.push_back(s);
  }
  return out;
}

void Procedure::commission() {
  // Named inputs and encoders are checked before anything moves.
  if (!options_.halls.empty()) named_inputs(m_.loop(), options_.halls);
  if (options_.encoder) encoder_index(m_.loop(), *options_.encoder);
  align(0.0);
  say(std::string("sweeping ") + fixed(plan_.sweep_turns, 1) + " electrical turns forward");
  const std::size_t sweep_start = m_.ticks().size();
  const double end = sweep_forward();
  say("sweeping back");
  sweep_to(end, 0.0, false);
  m_.stop_following();

  const auto halls = choose_halls(sweep_start);
  for (auto k : halls) report_.hall_pins.push_back(m_.loop().feedback().inputs[k].hal_pin);
  const std::size_t e = m_.scale()->encoder;
  report_.recorded = samples(e, halls);
  commission::AnalysisOptions analysis;
  analysis.pole_pairs = options_.pole_pairs;
  analysis.counts_per_turn = options_.counts_per_turn;
  analysis.hall_sensors_expected = !halls.empty();
  say(std::string("analysing ") + std::to_string(report_.recorded.size()) + " samples");
  const auto result = commission::analyse(report_.recorded, analysis);
  report_.result = result;
  report_.bldc = commission::bldc_settings(result);

  if (!result.encoder_direction || !result.counts_per_electrical_turn || !result.encoder_offset_counts) {
    report_.stop = StopReason::CouldNotTell;
    report_.message =
        "the analysis could not tell every value the closed-loop check needs (see the problems)";
    return;
  }
  Rotor rotor;
  rotor.scale = Scale{.encoder = e,
                      .direction = result.encoder_direction->value,
                      .counts_per_electrical_turn = result.counts_per_electrical_turn->value};
  const auto latch = std::find_if(report_.recorded.rbegin(), report_.recorded.rend(),
                                  [](const auto& s) { return s.index_seen; });
  rotor.zero_count = latch->latched_count + result.encoder_offset_counts->value;
  if (result.hall.sequence) rotor.halls_sequence = result.hall.sequence->value;
  rotor.halls = halls;
  m_.set_scale(rotor.scale, false);
  report_.check = closed_loop(rotor);
  if (!report_.check->passed) {
    report_.stop = StopReason::CheckFailed;
    report_.message = "the closed-loop check with the found values failed: " + report_.check->how;
    return;
  }
  // Halls looked for but not told apart (report_.notes says why) leave the pattern open.
  const bool complete = result.problems.empty() && (options_.no_halls || !halls.empty());
  report_.stop = complete ? StopReason::Completed : StopReason::CouldNotTell;
  report_.message = complete ? "commutation found and checked in closed loop"
                             : "checked in closed loop, but some values could not be told (see the problems)";
}

// The rotor as the setup sees it, from the index: turns open loop forward until the index
// latches (at most one mechanical turn). Without it the report says why (nullopt).
std::optional<Procedure::Rotor> Procedure::find_rotor(const BldcSetup& setup) {
  if (!setup.has_index)
    throw UsageError(
        "--check needs a setup with an index (bldc cfg qi or qhi: encoder-offset) to know the rotor angle");
  Rotor rotor;
  rotor.scale.encoder = encoder_index(m_.loop(), setup.encoder.value_or(0));
  rotor.scale.direction = setup.scale > 0 ? 1 : -1;
  rotor.scale.counts_per_electrical_turn = std::abs(static_cast<double>(setup.scale)) / (setup.poles / 2.0);
  report_.encoder_instance = m_.loop().feedback().encoders[rotor.scale.encoder].instance;
  // bldc reads the Halls only with cfg h; then the check holds them to the file's pattern.
  if (setup.uses_halls && setup.pattern) {
    for (const auto& row : commission::hall_table())
      if (row.bldc_pattern == setup.pattern) rotor.halls_sequence = row.sequence;
    if (!rotor.halls_sequence)
      throw UsageError("bldc pattern " + std::to_string(*setup.pattern) +
                       " is not one of bldc's Hall patterns");
    rotor.halls = setup.halls.empty() ? std::vector<std::size_t>{} : named_inputs(m_.loop(), setup.halls);
    for (auto k : rotor.halls) report_.hall_pins.push_back(m_.loop().feedback().inputs[k].hal_pin);
    if (rotor.halls.empty())
      report_.notes.push_back(
          "the Hall codes were not checked: the file wires no hostmot2 inputs into bldc's hall1..3 (or name "
          "them with --halls)");
  }
  // The index: turn open loop forward until it latches (at most one mechanical turn).
  align(0.0);
  m_.set_scale(rotor.scale, true);
  say("finding the index");
  const double dt = m_.loop().period().count() / 1000.0;
  std::optional<std::int64_t> latch;
  while (!latch && command_ < setup.poles / 2.0 + 1.0) {
    command_ += plan_.turns_per_s * dt;
    latch = m_.hold(plan_.current_a, command_).index_latch[rotor.scale.encoder];
  }
  m_.stop_following();
  if (!latch) {
    report_.stop = StopReason::CheckFailed;
    report_.message =
        "no index latched in a mechanical turn and more: the encoder's index is not connected, or the "
        "setup's poles and scale are wrong";
    return std::nullopt;
  }
  rotor.zero_count = *latch + setup.encoder_offset;
  return rotor;
}

void Procedure::check_only(const BldcSetup& setup) {
  const auto rotor = find_rotor(setup);
  if (!rotor) return;
  report_.check = closed_loop(*rotor);
  report_.stop = report_.check->passed ? StopReason::Completed : StopReason::CheckFailed;
  report_.message = report_.check->passed ? "the setup turns the motor both ways as commanded"
                                          : "the closed-loop check failed: " + report_.check->how;
}

// --- tune-axis: the mechanics -------------------------------------------------------------

// The move within the window under a position loop of the tool's own, commutated from the
// rotor's angle (as bldc would), then the fit. The loop (as mechanics::rehearse_identification
// rehearses it on the motor model): PID for the inertia guess at 4 Hz, or lower where the
// period's delay would eat its phase (3 Hz at 10 ms), or stiffer against the friction guess;
// its speed and its torque low-passed at 20 Hz so that it drives no resonance above. The
// torque stays within the plan's current (Motion clamps it too).
void Procedure::identify_axis(const BldcSetup& setup) {
  const auto rotor = find_rotor(setup);
  if (!rotor) return;
  const auto& id = *plan_.identify;
  const auto path = identification_path(id);
  const double dt = m_.loop().period().count() / 1000.0;
  const double pole_pairs = setup.poles / 2.0;
  const std::size_t e = rotor->scale.encoder;
  const auto shaft_rad = [&](const Tick& t) {
    return rotor->angle(t.counts[e]) / pole_pairs * 2 * std::numbers::pi;
  };
  const double w = 2 * std::numbers::pi * std::min(4.0, 0.03 / dt);
  const double inertia = id.inertia_guess_kgm2;
  const double kp = std::max(inertia * w * w, 10 * id.friction_guess_nm / path.amplitude_rad());
  const double kd = 2 * 0.8 * std::sqrt(kp * inertia), ki = kp * w / 5;
  const double smoothing = 1 - std::exp(-2 * std::numbers::pi * 20 * dt);
  const double most_nm = plan_.current_a * id.torque_constant_nm_per_a;
  say("identifying: back and forth for " + fixed(path.duration_s(), 1) + " s");
  const double origin = shaft_rad(m_.ticks().back());
  const double t0 = m_.ticks().back().t_s;
  double integral = 0, previous = 0, speed = 0, torque = 0, previous_t = t0;
  bool first = true;
  double torque_held = 0, angle_held = rotor->angle(m_.ticks().back().counts[e]);
  std::vector<HeldAngle> held;
  for (;;) {
    const Tick& now = m_.ticks().back();
    const double t = now.t_s - t0;
    if (t >= path.duration_s()) break;
    const double position = shaft_rad(now) - origin;
    if (!first) speed += smoothing * ((position - previous) / std::max(dt / 4, now.t_s - previous_t) - speed);
    first = false;
    previous = position;
    previous_t = now.t_s;
    const double error = path.position_rad(t) - position;
    integral += error * dt;
    const double wanted = kp * error + kd * (path.speed_rad_s(t) - speed) + ki * integral;
    torque = std::clamp(torque + smoothing * (wanted - torque), -most_nm, most_nm);
    // Where the rotor will be halfway through the period this torque holds (it is written
    // with the next packet): the angle the 8I20 keeps until then is then off by as little
    // as the period allows.
    const auto& ticks = m_.ticks();
    const Tick& before = ticks[ticks.size() > 1 ? ticks.size() - 2 : 0];
    const double electrical_speed = (rotor->angle(now.counts[e]) - rotor->angle(before.counts[e])) /
                                    std::max(dt / 4, now.t_s - before.t_s);
    const double theta = rotor->angle(now.counts[e]) + electrical_speed * 1.5 * dt;
    // The packet that writes this torque reads the encoder too: the sample is the torque
    // from that moment on, where the shaft was then.
    const Tick& applied = m_.drive(torque / id.torque_constant_nm_per_a, theta, theta);
    const double there = shaft_rad(applied) - origin;
    if (applied.command_taken) {  // a busy card keeps the last command it took
      torque_held = torque;
      angle_held = theta;
    }
    report_.motion.push_back({applied.t_s, there, torque_held});
    held.push_back({angle_held, rotor->angle(applied.counts[e]), applied.command_taken});
    report_.widest_turns = std::max(report_.widest_turns, std::abs(there) / (2 * std::numbers::pi));
  }
  if (!torque_in_effect(held)) return;
  say("fitting the mechanics to " + std::to_string(report_.motion.size()) + " samples");
  try {
    // Windows of several periods: the fit's speeds and integrals need samples in them.
    const mechanics::IdentifyOptions fit{.window_s = std::max(0.02, 10 * dt),
                                         .speed_span_s = std::max(0.004, 2 * dt)};
    report_.mechanics = mechanics::identify(report_.motion, fit);
    report_.fit = mechanics::fit_windows(report_.motion, *report_.mechanics, fit);  // the fit as made
    correct_for_current_loop(*report_.mechanics);
    if (!(report_.mechanics->inertia_kgm2.value > 0)) {
      report_.stop = StopReason::CouldNotTell;
      report_.message =
          "the current loop's share of the fitted inertia is all of it: is --torque-constant the motor's, "
          "and "
          "MAXCURRENT and the bus as the card reads them?";
      return;
    }
    report_.stop = StopReason::Completed;
    report_.message = "the mechanics identified within +-" + fixed(report_.widest_turns, 3) + " motor turns";
  } catch (const mechanics::IdentifyError& e) {
    report_.stop = StopReason::CouldNotTell;
    report_.message = std::string("the move did not identify the mechanics: ") + e.what();
  }
}

// The record's torques as the 8I20 gave them: each command times its share along the angle
// the card held while the rotor turned on (share_in_effect). On a host that keeps the 1 ms
// loop the shares are near 1 (the angle is carried to the period's middle); a stalled loop or
// a busy card (the last command stays in effect) holds a stale angle, and a fit of the
// commanded torque would read the lost torque as inertia. A record that lost too much is not
// fitted: the host did not keep the loop. Returns false (report_ says why) then.
bool Procedure::torque_in_effect(const std::vector<HeldAngle>& held) {
  auto& motion = report_.motion;
  std::size_t weak = 0;
  double lowest = 1;
  const auto not_taken = std::count_if(held.begin(), held.end(), [](const HeldAngle& h) { return !h.taken; });
  for (std::size_t j = 0; j < motion.size(); ++j) {
    const double to = j + 1 < held.size() ? held[j + 1].rotor : held[j].rotor;
    const double share = share_in_effect(held[j].angle, held[j].rotor, to);
    motion[j].torque_nm *= share;
    lowest = std::min(lowest, share);
    if (share < kLeastTorqueShare) ++weak;
  }
  report_.notes.push_back("the loop: " + std::to_string(not_taken) + " of " + std::to_string(held.size()) +
                          " commands a busy card did not take; the torque in effect at least " +
                          fixed(100 * lowest, 1) + "% of the command along the angle the 8I20 held");
  if (static_cast<double>(weak) <= kMostWeakShare * static_cast<double>(motion.size())) return true;
  report_.stop = StopReason::CouldNotTell;
  report_.message = "this host did not keep the " + fixed(timing::kIdentifyPeriod.count(), 0) +
                    " ms loop: in " + std::to_string(weak) + " of " + std::to_string(motion.size()) +
                    " periods the angle the 8I20 held gave under " + fixed(100 * kLeastTorqueShare, 0) +
                    "% of the torque; run it again on a quieter host (the fit was not made)";
  return false;
}

// The 8I20's current loop is a PI in the ANGLE frame (docs/motor-model.md) with nothing fed
// forward for the motor's back-EMF, Kt w / 1.5 on the q axis. As the axis accelerates that
// voltage ramps, and a PI follows a ramp with a steady error, (Kt a / 1.5) / Ki: the current,
// and the torque, fall short of the command in proportion to the acceleration, which a fit
// of commanded torque reads as inertia, Kt^2 / (1.5 Ki) more than the axis has (0.29 kg cm^2
// at the 8I20's default KQI with a 0.45 Nm/A motor: half the rotor's). Ki comes from the card's
// KQI at its MAXCURRENT and bus (motor::physical_gains), so that part is taken off.
void Procedure::correct_for_current_loop(mechanics::Mechanics& found) {
  const auto& pre = plan_.preflight;
  const auto gains = motor::physical_gains(pre.kqp, pre.kqi, pre.max_current_a, pre.bus_v);
  if (!(gains.ki_v_per_as > 0)) return;
  const double kt = plan_.identify->torque_constant_nm_per_a;
  const double lag = kt * kt / (1.5 * gains.ki_v_per_as);
  report_.notes.push_back("inertia: " + fixed(found.inertia_kgm2.value * 1e4, 3) +
                          " kg cm^2 as fitted, less " + fixed(lag * 1e4, 3) +
                          " kg cm^2 that the 8I20's current loop (KQI " + std::to_string(pre.kqi) +
                          ") lags the back-EMF by as the axis accelerates");
  found.inertia_kgm2.value -= lag;
}

// --- the closed-loop check ---------------------------------------------------------------

// Commutates with ANGLE = the rotor's angle (what bldc's rotor-angle gives the 8I20, which
// adds its lead) at sign x the check current, until the rotor has turned enough or the
// time is up. Returns the electrical turns moved, forward positive.
double Procedure::push(const Rotor& rotor, int sign, ClosedLoopCheck& check) {
  const double dt = m_.loop().period().count() / 1000.0;
  const std::size_t e = rotor.scale.encoder;
  const double start = rotor.angle(m_.ticks().back().counts[e]);
  double moved = 0;
  double amps = 0;
  for (double t = 0; t < timing::kCheckPushS && std::abs(moved) < kCheckEnoughTurns; t += dt) {
    const double theta = rotor.angle(m_.ticks().back().counts[e]);
    // A governor: the current creeps up from 0 while the rotor turns slower than the sweep
    // did, and drops to 0 when it is faster, so a light rotor is not flung (the torque
    // needed is found, not assumed).
    const auto& ticks = m_.ticks();
    const auto& before = ticks[ticks.size() > 3 ? ticks.size() - 4 : 0];
    const double speed =
        std::abs(theta - rotor.angle(before.counts[e])) / std::max(dt, ticks.back().t_s - before.t_s);
    amps = speed > 0.5 * plan_.turns_per_s
               ? 0.0
               : std::min(plan_.check_current_a, amps + plan_.check_current_a * dt / timing::kCheckRampS);
    const auto& tick = m_.drive(sign * amps, theta, theta);
    const double now = rotor.angle(tick.counts[e]);
    moved = now - start;
    if (rotor.halls_sequence && !rotor.halls.empty()) {
      const double sectors = now * 6.0;
      const double nearest = std::floor(sectors + 0.5);
      const auto k = static_cast<std::size_t>(((static_cast<long>(nearest) % 6) + 6) % 6);
      ++check.hall_samples;
      if (std::abs(sectors - nearest) < 0.25 &&
          hall_code(tick, rotor.halls) != rotor.halls_sequence->code_at_sector[k])
        ++check.hall_mismatches;
    }
  }
  // Brake: hold the current vector where the rotor is now, so it stops there.
  const double stop_at = rotor.angle(m_.ticks().back().counts[e]);
  for (double t = 0; t < timing::kCheckRestS; t += dt) m_.hold(plan_.check_current_a, stop_at);
  return moved;
}

// Holds the current vector at `at_turns` (the rotor's frame the setup gives) and returns
// how far the encoder's angle ends up from it, in electrical degrees.
double Procedure::hold_error(const Rotor& rotor, double at_turns) {
  const double dt = m_.loop().period().count() / 1000.0;
  const std::size_t e = rotor.scale.encoder;
  // The current ramps up where the rotor is, and the command then moves at the sweep's
  // speed: no step for the rotor to be flung by.
  double command = rotor.angle(m_.ticks().back().counts[e]);
  for (double t = 0; t < timing::kHoldRampS; t += dt)
    m_.hold(plan_.check_current_a * t / timing::kHoldRampS, command);
  const double step = plan_.turns_per_s * dt;
  while (std::abs(at_turns - command) > 1e-9) {
    command = at_turns > command ? std::min(at_turns, command + step) : std::max(at_turns, command - step);
    m_.hold(plan_.check_current_a, command);
  }
  for (double t = 0; t < timing::kHoldS; t += dt) m_.hold(plan_.check_current_a, at_turns);
  return wrap_turns(rotor.angle(m_.ticks().back().counts[e]) - at_turns) * 360.0;
}

ClosedLoopCheck Procedure::closed_loop(const Rotor& rotor) {
  ClosedLoopCheck check;
  check.bound_deg = options_.check_bound_deg;
  for (int sign : {1, -1}) {
    say(sign > 0 ? "checking: positive torque" : "checking: negative torque");
    DirectionCheck d;
    d.torque_sign = sign;
    d.moved_electrical_turns = push(rotor, sign, check);
    d.passed = d.moved_electrical_turns * sign >= kCheckMinTurns;
    check.directions.push_back(d);
  }
  say("checking: holds");
  const double here = rotor.angle(m_.ticks().back().counts[rotor.scale.encoder]);
  for (double at : {here + 0.15, here - 0.15})  // from each side: friction lags them opposite ways
    check.hold_errors_deg.push_back(hold_error(rotor, at));
  const bool turns =
      std::all_of(check.directions.begin(), check.directions.end(), [](const auto& d) { return d.passed; });
  const bool holds = std::all_of(check.hold_errors_deg.begin(), check.hold_errors_deg.end(),
                                 [&](double e) { return std::abs(e) <= check.bound_deg; });
  const bool halls =
      check.hall_samples == 0 || static_cast<double>(check.hall_mismatches) <=
                                     kHallMismatchLimit * static_cast<double>(check.hall_samples);
  check.passed = turns && holds && halls;
  check.how = std::string("positive torque moved ") + fixed(check.directions[0].moved_electrical_turns, 2) +
              " electrical turns, negative " + fixed(check.directions[1].moved_electrical_turns, 2) +
              " (each must move at least " + fixed(kCheckMinTurns, 2) + " its own way); holds off by " +
              fixed(check.hold_errors_deg[0], 1) + " and " + fixed(check.hold_errors_deg[1], 1) +
              " electrical degrees (bound " + fixed(check.bound_deg, 1) + ")";
  if (check.hall_samples > 0)
    check.how += std::string("; Hall codes off the pattern's sector in ") +
                 std::to_string(check.hall_mismatches) + " of " + std::to_string(check.hall_samples) +
                 " samples";
  return check;
}

eth::NormalModeOptions loop_options(const CommissionPlan& plan, const CommissionOptions& options,
                                    const Session& session) {
  const auto period = plan.identify ? timing::kIdentifyPeriod : options.period;
  // A lost reply must not cost the watchdog: two periods' wait at most.
  return timing::normal_mode(session.options().link, period, period * 2);
}

}  // namespace

CommissionReport run_commission(Session& session, const CommissionPlan& plan,
                                const CommissionOptions& options, const CommissionProgress& progress) {
  CommissionReport report;
  report.plan = plan;
  std::unique_ptr<eth::DriveLoop> loop;
  // Outlives the try: a run stopped midway still reports the cycles it drove.
  std::optional<Motion> motion;
  const auto started = std::chrono::steady_clock::now();
  const eth::RealtimePriority realtime;
  if (!realtime.granted())
    report.notes.push_back(
        "the drive loop ran without realtime priority (needs root or CAP_SYS_NICE): on a "
        "loaded machine a late DOIT may let the 8I20's watchdog stop the run");
  try {
    loop = eth::DriveLoop::open(plan.preflight.target, loop_options(plan, options, session));
    motion.emplace(*loop, plan, options, session.cancel());
    Procedure procedure(*motion, plan, options, progress, report);
    if (plan.identify)
      procedure.identify_axis(*plan.check);
    else if (plan.check)
      procedure.check_only(*plan.check);
    else
      procedure.commission();
  } catch (const Abort& abort) {
    report.stop = abort.reason();
    report.message = abort.what();
  } catch (const eth::RunningHostError& e) {
    report.stop = StopReason::OtherHost;
    report.message = e.what();
  } catch (const UsageError&) {
    if (loop) loop->stop();
    throw;
  } catch (const link::TimeoutError& e) {
    report.stop = StopReason::LinkLost;
    report.message = e.what();
  } catch (const std::exception& e) {
    report.stop = StopReason::Error;
    report.message = e.what();
  }
  if (motion) report.samples = motion->ticks().size();
  if (report.stop != StopReason::Signal && session.stop_requested()) {
    report.notes.push_back("a stop signal arrived as the run ended: " + report.message);
    report.stop = StopReason::Signal;
    report.message = "stopped by " + session.cancel().cause();
  }
  if (loop) {
    session.cancel().acknowledge("setting the current to 0 and stopping the SSERIAL port");
    try {
      loop->stop();
      report.current_zeroed = true;
    } catch (const std::exception& e) {
      report.zero_note = std::string("the stop was not confirmed (") + e.what() +
                         "): the 8I20's watchdog disables its output 40 ms after the last DOIT";
    }
    report.doit = loop->stats();
  } else {
    report.current_zeroed = true;  // never started: no current was commanded
    report.zero_note = "normal mode never started";
  }
  report.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return report;
}

std::string_view stop_reason_name(StopReason reason) {
  switch (reason) {
    case StopReason::Completed: return "completed";
    case StopReason::CouldNotTell: return "could-not-tell";
    case StopReason::CheckFailed: return "check-failed";
    case StopReason::Stall: return "stall";
    case StopReason::Runaway: return "runaway";
    case StopReason::TravelLimit: return "travel-limit";
    case StopReason::NotFollowing: return "not-following";
    case StopReason::TimeLimit: return "time-limit";
    case StopReason::Fault: return "fault";
    case StopReason::OtherHost: return "other-host";
    case StopReason::Signal: return "signal";
    case StopReason::LinkLost: return "link-lost";
    case StopReason::Error: return "error";
  }
  return "error";
}

Outcome CommissionReport::outcome() const {
  if (!current_zeroed) return Outcome::Uncertain;
  switch (stop) {
    case StopReason::Completed: return Outcome::Done;
    case StopReason::Signal: return Outcome::Interrupted;
    case StopReason::LinkLost:
    case StopReason::Error: return Outcome::Failed;
    default: return Outcome::Refused;
  }
}

}  // namespace i20::ops
