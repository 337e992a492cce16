// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/commission/commission_motion.hpp"

#include <algorithm>
#include <cmath>

#include "commission/format.hpp"
#include "faults/decode.hpp"
#include "hostmot2/hostmot2.hpp"
#include "lbp/bytes.hpp"
#include "link/link.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops::commission_detail {

using commission::fixed;
using Clock = std::chrono::steady_clock;

namespace {

std::uint16_t angle_word(double turns) {
  const double frac = turns - std::floor(turns);
  return static_cast<std::uint16_t>(static_cast<std::uint32_t>(std::lround(frac * 65536.0)) & 0xFFFFu);
}

std::string fault_names(std::uint16_t fault) {
  std::string names;
  for (const auto& bit : faults::decode_fault(fault).bits) {
    if (!names.empty()) names += ", ";
    names += bit.label();
  }
  return names;
}

}  // namespace

Motion::Motion(eth::DriveLoop& loop, const CommissionPlan& plan, const CommissionOptions& options,
               const Cancel& cancel)
    : loop_(loop), plan_(plan), options_(options), cancel_(cancel), start_(Clock::now()) {
  foreign_at_start_ = loop_.foreign_packets();
}

double Motion::elapsed_s(Clock::time_point at) const {
  return std::chrono::duration<double>(at - start_).count();
}

// The readings' time on the card's microsecond timer, unwrapped and placed on the run's clock
// at the first reading. Neither end of the host's round trip is that time: a host put aside
// while a reply waited, or a card's packet that waited in the network, shows as a burst of
// speed on the host's clock (a 1 ms loop's runaway guard once tripped on one). The host's clock
// resolves the timer's wraps (a gap past 65.536 ms wraps it).
double Motion::card_time_s(const eth::DriveReading& reading, double host_s) {
  constexpr double kWrapS = 65536e-6;
  if (!last_card_us_) {
    card_s_ = host_s;
  } else {
    const double on_timer = static_cast<std::uint16_t>(reading.card_microseconds - *last_card_us_) * 1e-6;
    const double wraps = std::max(0.0, std::round((host_s - last_host_s_ - on_timer) / kWrapS));
    card_s_ += on_timer + wraps * kWrapS;
  }
  last_card_us_ = reading.card_microseconds;
  last_host_s_ = host_s;
  return card_s_;
}

const Tick& Motion::drive(double amps, double angle_turns, double command_turns) {
  const double max = plan_.preflight.max_current_a;
  const double clamped = std::clamp(amps, -plan_.current_a, plan_.current_a);  // never above the plan
  const auto q = static_cast<std::int16_t>(std::lround(clamped / max * 32767.0));
  eth::DriveReading reading;
  do {
    reading = loop_.cycle(eth::DriveSetpoint{.qsetpoint = q, .angle = angle_word(angle_turns)});
    if (cancel_.requested()) throw Abort(StopReason::Signal, "stopped by " + cancel_.cause());
  } while (reading.encoders.empty());  // a lost reply: the next cycle sends the same again
  Tick tick;
  tick.host_s = elapsed_s(reading.sent);
  tick.t_s = card_time_s(reading, tick.host_s);
  tick.command_turns = command_turns;
  tick.command_taken = reading.command_taken;
  unwrap(reading, tick);
  ticks_.push_back(std::move(tick));
  guard(reading, ticks_.back());
  return ticks_.back();
}

void Motion::unwrap(const eth::DriveReading& reading, Tick& tick) {
  const bool first = last16_.empty();
  if (first) last16_.resize(reading.encoders.size());
  for (std::size_t e = 0; e < reading.encoders.size(); ++e) {
    const auto& r = reading.encoders[e];
    const std::int64_t previous = first ? 0 : ticks_.back().counts[e];
    const std::int64_t count =
        first ? r.count
              : previous + static_cast<std::int16_t>(static_cast<std::uint16_t>(r.count - last16_[e]));
    last16_[e] = r.count;
    tick.counts.push_back(count);
    tick.index_latch.push_back(
        r.index_latched
            ? std::optional<std::int64_t>(
                  count + static_cast<std::int16_t>(static_cast<std::uint16_t>(r.latched - r.count)))
            : std::nullopt);
  }
  tick.input_words = reading.input_words;
}

void Motion::guard(const eth::DriveReading& reading, const Tick& tick) {
  // After a start INTERFACE1 holds the card's name, not FAULT and STATUS: someone else
  // started the channel again under us.
  const std::uint32_t interface1 = static_cast<std::uint32_t>(reading.fault) << 16 | reading.status;
  if (reading.fresh && interface1 == lbp::hm2::sslbp::kName8i20)
    throw Abort(StopReason::OtherHost,
                "the 8I20's channel was started again under this run (INTERFACE1 reads its name, "
                "\"8I20\"): another host (LinuxCNC?) took the card");
  // The WATCHDOGFAULT the preflight found latched (how the last session ended) is cleared by
  // the normal start on the card a few milliseconds after it: a fast loop reads it in its first
  // cycles. Only that, only until the first clean reading and at most kClearFaultWait.
  if (reading.fresh && reading.fault == 0) start_fault_clearing_ = false;
  const bool clearing = start_fault_clearing_ && reading.fault == plan_.preflight.fault &&
                        tick.host_s < std::chrono::duration<double>(timing::kClearFaultWait).count();
  if (reading.fresh && reading.fault != 0 && !clearing)
    throw Abort(StopReason::Fault, std::string("the 8I20 latched FAULT ") + lbp::hex_value(reading.fault, 4) +
                                       " (" + fault_names(reading.fault) + ") " + fixed(tick.host_s, 2) +
                                       " s into the run; it disabled its output");
  if (tick.host_s > plan_.time_limit_s)
    throw Abort(StopReason::TimeLimit,
                std::string("the time limit (") + fixed(plan_.time_limit_s, 0) + " s) ran out");
  if (++cycles_ % timing::kCommissionHostCheckEvery == 0) check_for_other_host();
  guard_motion(tick);
}

// The card's packet counters, between DOITs. A read that goes unanswered (a host's hiccup of a
// few milliseconds outlasts a 1 ms loop's reply wait) is tried again at the next check; the
// DOITs' own missed replies tell a card that stopped, and the counters count from the run's
// start, so a check tried again misses nothing. kCommissionHostCheckMisses in a row end the
// run: the card's counters could not be read to see another host.
void Motion::check_for_other_host() {
  std::uint32_t foreign = 0;
  try {
    foreign = loop_.foreign_packets();
    unanswered_host_checks_ = 0;
  } catch (const link::TimeoutError&) {
    if (++unanswered_host_checks_ >= timing::kCommissionHostCheckMisses) throw;
    return;
  }
  if (foreign > foreign_at_start_ + timing::kCommissionForeignPackets)
    throw Abort(StopReason::OtherHost, std::string("another host sent the card ") +
                                           std::to_string(foreign - foreign_at_start_) +
                                           " packet(s) during the run (LinuxCNC?): stopped so that two hosts do "
                                           "not drive one 8I20");
}

void Motion::guard_motion(const Tick& tick) {
  if (!scale_) {
    // Before the scale is known the inputs that change tell a rotor that runs: a Hall
    // sensor changes twice per electrical turn.
    const std::size_t n = ticks_.size();
    if (n % 10 != 0 || n < 2) return;
    const auto changes = input_changes(0, n);
    const unsigned most = changes.empty() ? 0 : *std::max_element(changes.begin(), changes.end());
    double travel = 0;
    for (std::size_t i = 1; i < n; ++i)
      travel += std::abs(ticks_[i].command_turns - ticks_[i - 1].command_turns);
    if (most > 2 * (travel + 1.5) + 2)
      throw Abort(StopReason::Runaway, std::string("an input changed ") + std::to_string(most) +
                                           " times while the command moved " + fixed(travel, 2) +
                                           " electrical turns: the rotor runs away");
    return;
  }
  const auto& s = *scale_;
  const double cpe = s.counts_per_electrical_turn;
  const std::int64_t count = tick.counts[s.encoder];
  const double travel = std::abs(static_cast<double>(count - start_count_)) / cpe;
  if (travel > plan_.max_electrical_turns)
    throw Abort(StopReason::TravelLimit, std::string("the rotor turned ") + fixed(travel, 2) +
                                             " electrical turns, beyond the plan's " +
                                             fixed(plan_.max_electrical_turns, 1));
  const auto window = static_cast<std::size_t>(
      std::max<std::int64_t>(1, timing::kCommissionSpeedSpan / loop_.period()));
  if (ticks_.size() > window) {
    const auto& then = ticks_[ticks_.size() - 1 - window];
    const double speed =
        std::abs(static_cast<double>(count - then.counts[s.encoder])) / cpe / (tick.t_s - then.t_s);
    if (speed > plan_.runaway_turns_per_s)
      throw Abort(StopReason::Runaway, std::string("the rotor turned at ") + fixed(speed, 1) +
                                           " electrical turns/s, above the limit " +
                                           fixed(plan_.runaway_turns_per_s, 1) + ": runaway");
  }
  if (follow_) {
    const double expected = follow_count_ + s.direction * cpe * (tick.command_turns - follow_command_);
    const double off = std::abs(static_cast<double>(count) - expected) / cpe;
    if (off > options_.follow_tolerance_turns)
      throw Abort(
          StopReason::NotFollowing,
          std::string("the rotor is ") + fixed(off, 2) +
              " electrical turns from where the command puts it (limit " +
              fixed(options_.follow_tolerance_turns, 2) +
              "): it slipped, or something else moves it (a load, a brake dragging, too little current)");
  }
}

void Motion::set_scale(const Scale& scale, bool follow) {
  const bool first = !scale_;
  scale_ = scale;
  if (first) start_count_ = ticks_.front().counts[scale.encoder];
  follow_ = follow;
  follow_count_ = ticks_.back().counts[scale.encoder];
  follow_command_ = ticks_.back().command_turns;
}

bool Motion::input_bit(const Tick& tick, std::size_t input) const {
  const auto& in = loop_.feedback().inputs.at(input);
  return (tick.input_words.at(in.word) >> in.bit) & 1u;
}

std::vector<unsigned> Motion::input_changes(std::size_t from, std::size_t to) const {
  const auto& inputs = loop_.feedback().inputs;
  std::vector<unsigned> changes(inputs.size(), 0);
  for (std::size_t i = from + 1; i < to && i < ticks_.size(); ++i)
    for (std::size_t k = 0; k < inputs.size(); ++k)
      if (input_bit(ticks_[i], k) != input_bit(ticks_[i - 1], k)) ++changes[k];
  return changes;
}

}  // namespace i20::ops::commission_detail
