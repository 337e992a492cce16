// SPDX-License-Identifier: GPL-2.0-or-later
// The read-only half of `i20 commission`: the preflight and the plan the user confirms.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "commission/format.hpp"
#include "eth/anything_io.hpp"
#include "eth/udp_client.hpp"
#include "faults/decode.hpp"
#include "lbp/bytes.hpp"
#include "mechanics/excitation.hpp"
#include "ops/commission/commission.hpp"
#include "ops/commission/commission_motion.hpp"
#include "ops/core/read.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

using commission::fixed;

namespace {

// The 8I20 manual's operational bus range is 24 to 400 V; above 385 V its brake switches
// on by itself (MOTOR BRAKE), so a bus there is not a bench to commission on.
constexpr double kMinBusV = 24.0;
constexpr double kMaxBusV = 385.0;

void check_options(const CommissionOptions& o) {
  auto positive = [](double v, const char* what) {
    if (!(v > 0) || !std::isfinite(v)) throw UsageError(std::string(what) + " must be a positive number");
  };
  positive(o.current_fraction, "the current fraction");
  if (o.current_fraction > 1.0) throw UsageError("the current fraction is of MAXCURRENT: at most 1");
  positive(o.sweep_turns, "--sweep-turns");
  positive(o.turns_per_s, "--turns-per-second");
  positive(o.time_limit_s, "--time-limit");
  positive(o.align_s, "the align time");
  if (o.sweep_turns < 1.5) throw UsageError("--sweep-turns: at least 1.5 electrical turns each way");
  if (o.turns_per_s > 10) throw UsageError("--turns-per-second: at most 10 electrical turns per second");
  if (o.current_amps) positive(*o.current_amps, "--current");
  if (o.pole_pairs && *o.pole_pairs < 1) throw UsageError("--poles: at least 2 (one pole pair)");
  if (o.counts_per_turn && *o.counts_per_turn < 4) throw UsageError("--counts-per-rev: at least 4");
  if (o.no_halls && !o.halls.empty()) throw UsageError("--halls and --no-halls contradict each other");
  if (!o.halls.empty() && o.halls.size() != 3) throw UsageError("--halls: three inputs, Hall 1, 2, 3");
  if (o.hal_fragment && o.no_halls)
    throw UsageError(
        "-o with --no-halls: no HAL fragment can be written for a motor without Hall sensors (bldc's q modes "
        "without h align the rotor through its own A/B/C outputs, which the 8I20 does not take)");
  if (o.hal_fragment && o.check_file)
    throw UsageError("-o with --check: the setup checked is the file's own; nothing new would be written");
  if (o.identify) {
    const auto& id = *o.identify;
    if (!o.check_file)
      throw UsageError(
          "tune-axis needs the axis's commutation: --check FILE.hal (what i20 commission -o wrote)");
    positive(id.half_window_turns, "--travel");
    positive(id.duration_s, "--duration");
    positive(id.torque_constant_nm_per_a, "--torque-constant");
    positive(id.inertia_guess_kgm2, "--inertia-guess");
    if (id.friction_guess_nm < 0 || !std::isfinite(id.friction_guess_nm))
      throw UsageError("--friction-guess must be 0 or more");
    (void)commission_detail::identification_path(id);  // a window too short: refused before the card is asked
  }
}

double reading_of(const std::vector<Reading>& readings, std::size_t i, const char* name) {
  if (!readings.at(i).fact())
    throw Error(std::string("commission needs ") + name + " read as a fact: " + unknown_text(readings[i]),
                ErrorKind::Refused);
  return static_cast<double>(*readings[i].raw);
}

Preflight read_preflight(Session& session) {
  const auto& endpoint = session.endpoint();
  if (!endpoint.is_eth())
    throw UsageError(
        "commission drives the motor, which needs normal mode over Ethernet (a 7I96S or 7I92T: --eth IP or "
        "eth://IP/chN); setup mode over a 3I21/3I22 serial link drives no motor (W6 down disables the "
        "drive)");
  Preflight p;
  p.target = eth::parse_target(endpoint.eth_url);
  {
    Amp& amp = session.amp();  // the passthrough open refuses a running host
    p.card = amp.describe();
    const auto readings =
        read_values(amp, std::vector<std::string>{"FAULT", "BUSV", "MAXCURRENT", "KQP", "KQI"});
    p.fault = static_cast<std::uint16_t>(reading_of(readings, 0, "FAULT"));
    p.bus_v = reading_of(readings, 1, "BUSV") / 100.0;                // 10 mV
    p.max_current_a = reading_of(readings, 2, "MAXCURRENT") / 100.0;  // 10 mA
    p.kqp = static_cast<std::int64_t>(reading_of(readings, 3, "KQP"));
    p.kqi = static_cast<std::int64_t>(reading_of(readings, 4, "KQI"));
  }
  session.reconnect();  // the passthrough is closed before normal mode starts
  // WATCHDOGFAULT alone is how every normal-mode session ends (the host stops its DOITs: an
  // earlier run of this command, LinuxCNC's exit); the normal start clears it.
  constexpr std::uint16_t kWatchdogFault = 0x0001;
  if (p.fault == kWatchdogFault) {
    p.note =
        "FAULT holds only WATCHDOGFAULT: the last host stopped sending DOITs, as every normal-mode session "
        "ends; "
        "the normal start clears it";
  } else if (p.fault != 0) {
    std::string names;
    for (const auto& bit : faults::decode_fault(p.fault).bits) {
      if (!names.empty()) names += ", ";
      names += bit.label();
    }
    throw Error(std::string("the 8I20 has latched faults (FAULT ") + lbp::hex_value(p.fault, 4) + ": " +
                    names +
                    "); find their cause first (i20 faults), then clear them (i20 clear-faults): a normal "
                    "start would clear them unseen",
                ErrorKind::Refused);
  }
  if (p.bus_v < kMinBusV || p.bus_v > kMaxBusV)
    throw Error(std::string("the motor bus reads ") + fixed(p.bus_v, 1) + " V: commissioning needs " +
                    fixed(kMinBusV, 0) + ".." + fixed(kMaxBusV, 0) +
                    " V (8I20 manual: 24 to 400 V; its brake switches on at 385 V)",
                ErrorKind::Refused);
  if (!(p.max_current_a > 0))
    throw Error("MAXCURRENT is 0 A: the 8I20 would drive no current", ErrorKind::Refused);
  eth::UdpClient bus(p.target.host_port.ip, p.target.host_port.port,
                     timing::udp(session.options().link, RetryPolicy{}));
  p.board = eth::identify(bus).card_name;
  const auto info = eth::read_hostmot2(bus);
  if (eth::feedback_map(info).encoders.empty())
    throw Error("the card's configuration has no encoder (quadrature counter): commissioning needs one",
                ErrorKind::Refused);
  return p;
}

}  // namespace

namespace commission_detail {

// The identification's path for the window, or UsageError naming the least window that would
// do, in motor turns as the plan speaks.
mechanics::Excitation identification_path(const AxisIdentification& id) {
  try {
    return mechanics::Excitation(
        {.half_travel_rad = id.half_window_turns * 2 * std::numbers::pi, .duration_s = id.duration_s});
  } catch (const mechanics::IdentifyError&) {
    const double least = mechanics::Excitation::least_half_travel_rad() / (2 * std::numbers::pi);
    throw UsageError(std::string("--travel: +-") + fixed(id.half_window_turns, 3) +
                     " motor turns is too short to identify in: the move needs at least +-" +
                     fixed(least, 3) + " motor turns (" + fixed(2 * least, 3) + " turns of travel in all)");
  }
}

}  // namespace commission_detail

CommissionPlan prepare_commission(Session& session, const CommissionOptions& options) {
  check_options(options);
  CommissionPlan plan;
  // The --check file is read before the card is asked: a file for another axis asks nothing.
  if (options.check_file && session.endpoint().is_eth()) {
    const auto& f = *options.check_file;
    const auto channel = eth::parse_target(session.endpoint().eth_url).channel;
    plan.check = merge_check_options(read_bldc_setup(f.text, f.file, channel), options, f.file);
  }
  if (options.identify && (!plan.check || !plan.check->has_index))
    throw UsageError(
        "tune-axis needs a setup with an index (bldc cfg qi or qhi: encoder-offset) to know the "
        "rotor angle exactly");
  plan.preflight = read_preflight(session);
  const double max = plan.preflight.max_current_a;
  plan.current_a = std::min(options.current_amps.value_or(options.current_fraction * max), max);
  if (options.current_amps && *options.current_amps > max)
    throw Error(std::string("--current ") + fixed(*options.current_amps, 2) + " A is above MAXCURRENT " +
                    fixed(max, 2) + " A",
                ErrorKind::Refused);
  plan.check_current_a = plan.current_a * options.check_current_fraction;
  plan.align_s = options.align_s;
  plan.ramp_s = std::min(options.ramp_s, options.align_s);
  plan.sweep_turns = options.sweep_turns;
  plan.turns_per_s = options.turns_per_s;
  plan.time_limit_s = options.time_limit_s;
  plan.runaway_turns_per_s = options.runaway_factor * options.turns_per_s;
  // Align: at most half a turn; sweep: out and back; the check: about two turns each way.
  constexpr double kCheckTurns = 2.5;
  const double check_s = 2.4;
  if (options.identify) {
    const auto path = commission_detail::identification_path(*options.identify);
    const double pole_pairs = plan.check->poles / 2.0;
    plan.identify = options.identify;
    plan.identify_peak_turns_per_s = path.peak_speed_rad_s() / (2 * std::numbers::pi);
    // The index search (up to a mechanical turn and one electrical more), then the window,
    // with room for the loop's following error; faster than twice the move's top: runaway.
    plan.max_electrical_turns = 1.0 + pole_pairs * (1.0 + 1.25 * options.identify->half_window_turns) +
                                options.follow_tolerance_turns;
    plan.max_mechanical_turns = plan.max_electrical_turns / pole_pairs;
    plan.runaway_turns_per_s =
        std::max(plan.runaway_turns_per_s, 2 * pole_pairs * plan.identify_peak_turns_per_s);
    plan.estimated_s = options.align_s + (1.0 + pole_pairs) / options.turns_per_s + path.duration_s();
  } else if (plan.check) {
    plan.max_electrical_turns = kCheckTurns + 1.0 + plan.check->poles / 2.0;  // + finding the index
    plan.estimated_s = check_s + 1.0 + plan.check->poles / 2.0 / options.turns_per_s;
    plan.max_mechanical_turns = plan.max_electrical_turns / (plan.check->poles / 2.0);
  } else {
    // Twice unless both nameplate figures are given: the distance between two passes gives
    // the counts per turn, or checks given ones that alone would set the pole pairs unseen
    // (a wrong --counts-per-rev with the right counts per electrical turn commutates, and
    // names the wrong poles and scale). With both given, the sweep checks them together.
    plan.index_passes = options.counts_per_turn && options.pole_pairs ? 1 : 2;
    // The first pass comes within a mechanical turn, the second one turn later.
    plan.search_turns =
        std::max(options.sweep_turns,
                 options.pole_pairs ? plan.index_passes * *options.pole_pairs + 0.5 : options.search_turns);
    plan.max_electrical_turns = plan.search_turns + options.follow_tolerance_turns + 0.5 + kCheckTurns;
    plan.estimated_s = options.align_s + 2 * plan.search_turns / options.turns_per_s + check_s;
    if (options.pole_pairs) plan.max_mechanical_turns = plan.max_electrical_turns / *options.pole_pairs;
  }
  if (plan.estimated_s * 1.5 > plan.time_limit_s)
    throw UsageError(std::string("--time-limit ") + fixed(plan.time_limit_s, 0) +
                     " s is too short for the plan (about " + fixed(plan.estimated_s, 1) + " s)");
  return plan;
}

std::vector<std::string> CommissionPlan::lines() const {
  std::vector<std::string> out;
  out.push_back("card: " + preflight.card + "; bus " + fixed(preflight.bus_v, 1) + " V, " +
                (preflight.fault == 0 ? "no latched faults" : "only WATCHDOGFAULT latched") +
                ", MAXCURRENT " + fixed(preflight.max_current_a, 2) + " A");
  if (!preflight.note.empty()) out.push_back(preflight.note);
  if (!check) {
    out.push_back(std::string("align: the current ramps to ") + fixed(current_a, 2) + " A in " +
                  fixed(ramp_s, 1) + " s at electrical angle 0 and holds for " + fixed(align_s, 1) +
                  " s (the rotor jumps up to half an "
                  "electrical turn)");
    std::string sweep = std::string("sweep: ") + fixed(sweep_turns, 1);
    if (search_turns > sweep_turns)
      sweep += std::string(" to ") + fixed(search_turns, 1) + " (on until the index has passed " +
               (index_passes == 1 ? std::string("once") : std::string("twice")) + ")";
    sweep += std::string(" electrical turns forward and back at ") + fixed(turns_per_s, 2) + " turns/s, " +
             fixed(current_a, 2) + " A";
    out.push_back(sweep);
    // Said before anything moves: a motor with more pole pairs than the search covers ends
    // "could not tell" after the whole search.
    if (!max_mechanical_turns && index_passes == 2)
      out.push_back("without --poles the index passes twice within " + fixed(search_turns, 0) +
                    " electrical turns only on a motor of up to " +
                    std::to_string(static_cast<int>(search_turns / 2)) +
                    " pole pairs: for more, give --poles (and --counts-per-rev)");
  }
  if (identify) {
    out.push_back("find the index: forward at " + fixed(current_a, 2) +
                  " A, at most one motor turn (the axis moves: give it room)");
    out.push_back("identify: back and forth within +-" + fixed(identify->half_window_turns, 3) +
                  " motor turns about where the index was found, for " + fixed(identify->duration_s, 1) +
                  " s, at most " + fixed(identify_peak_turns_per_s, 2) +
                  " motor turns/s, under a position loop of its own; torque at most " + fixed(current_a, 2) +
                  " A (--current)");
    out.push_back(
        "afterwards the current is 0: a vertical axis must be held by its brake or a counterweight");
  } else {
    out.push_back(std::string("check: closed loop at ") + fixed(check_current_a, 2) +
                  " A, one to two electrical turns each way, then two holds");
  }
  std::string travel =
      std::string("the rotor may turn at most ") + fixed(max_electrical_turns, 1) + " electrical turns";
  travel += max_mechanical_turns ? std::string(" (") + fixed(*max_mechanical_turns, 2) + " mechanical turns)"
                                 : std::string(" (as many mechanical turns for a one-pole-pair motor)");
  out.push_back(travel);
  out.push_back(
      std::string("stops at once: faster than ") + fixed(runaway_turns_per_s, 1) +
      " electrical turns/s, a rotor that does not follow, a latched fault, another host, a signal; after " +
      fixed(time_limit_s, 0) + " s in all (about " + fixed(estimated_s, 1) + " s planned)");
  return out;
}

}  // namespace i20::ops
