// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 commission`: find a motor's commutation on an 8I20 over Ethernet (encoder direction,
// counts per electrical turn and pole pairs, bldc's Hall `pattern`, the index's
// `encoder-offset`), check it in closed loop, and say what bldc needs. Every decision lives
// here; the app parses options and renders.
//
// Safety by construction (docs/commissioning.md):
//  1. prepare_commission(): read-only preflight over setup-mode passthrough (card and map,
//     the running-host guard, bus voltage in 24..385 V, no latched FAULT, MAXCURRENT, an
//     encoder on the card) and a plan: current (a fraction of MAXCURRENT, never above it),
//     angles, time, and the most the rotor may turn. The app prints it and asks.
//  2. run_commission(): normal mode through eth::DriveLoop (one DOIT every period, well
//     inside the 8I20's 40 ms watchdog, which stays the backstop if the tool dies). Align
//     with a ramped current, sweep the electrical angle slowly forward and back recording
//     samples, commission::analyse, then the closed-loop check. Every cycle checks: a stop
//     signal, a FAULT the 8I20 latched, the time limit, another host's packets, and once the
//     rotor's scale is known, runaway speed, travel and a rotor that does not follow the
//     command; the first forward electrical turn checks for a stall. Every way out ends
//     with QSETPOINT 0 sent and the port stopped, then the report says what happened.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "commission/bldc_settings.hpp"
#include "commission/result.hpp"
#include "commission/sample.hpp"
#include "eth/drive_loop.hpp"
#include "eth/target.hpp"
#include "mechanics/identify.hpp"
#include "ops/core/outcome.hpp"
#include "ops/core/session.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

// An existing bldc setup to check (`--check FILE.hal`): bldc's own values for the 8I20 being
// checked, and what the file wires into that bldc instance.
struct BldcSetup {
  int instance = 0;  // bldc.N
  std::optional<int> pattern;
  int poles = 0;           // bldc's `poles`: twice the pole pairs
  std::int64_t scale = 0;  // counts per mechanical turn, signed: the encoder's direction
  std::int64_t encoder_offset = 0;
  bool has_index = false;               // cfg has i: encoder_offset applies
  bool uses_halls = false;              // cfg has h: bldc commutates from the Halls (until the index, with i)
  std::optional<unsigned> encoder;      // the hm2 encoder netted to bldc.N.rawcounts
  std::vector<std::string> halls;       // the inputs netted to bldc.N.hall1..3, after the board prefix
  std::optional<unsigned> amp_channel;  // the 8I20 channel bldc.N's rotor-angle drives
};

// The file `--check` names, read against the target when the plan is made.
struct CheckFile {
  std::string text;
  std::string file;
};

// `i20 tune-axis` (issue 43): the axis's mechanics identified by a gentle back-and-forth
// move within a travel window, commutated with the --check file's setup (its index and
// encoder-offset, as LinuxCNC's bldc would). The move follows mechanics::Excitation under a
// position loop of the tool's own (3 to 4 Hz for the inertia guess, or stiffer against the
// friction guess); mechanics::identify fits the record.
struct AxisIdentification {
  double half_window_turns = 0;  // motor turns, +- about where the index search ends
  double duration_s = 8;
  double torque_constant_nm_per_a = 0;
  double inertia_guess_kgm2 = 0;  // sets the loop's gain only; the result replaces it
  double friction_guess_nm = 0;
};

struct CommissionOptions {
  std::optional<unsigned> encoder;  // hm2 encoder instance; nullopt: the one that moves
  // Hall inputs as hostmot2 names them after the board prefix (gpio.013.in,
  // inm.00.input-00), in Hall 1, 2, 3 order. Empty: the three inputs that change.
  std::vector<std::string> halls;
  bool no_halls = false;  // the motor has none: do not look for them
  std::optional<int> pole_pairs;
  std::optional<std::int64_t> counts_per_turn;
  std::optional<double> current_amps;  // default: current_fraction x MAXCURRENT
  double current_fraction = 0.2;
  double check_current_fraction = 0.5;  // of the sweep current
  double align_s = timing::kCommissionAlignS;
  double ramp_s = timing::kCommissionRampS;
  double sweep_turns = 3.0;                             // electrical turns each way
  double turns_per_s = 1.5;                             // electrical turns per second
  double time_limit_s = timing::kCommissionTimeLimitS;  // the whole run
  // Without --poles or --counts-per-rev: how far the sweep may go looking for a second
  // index pulse (electrical turns; a motor of up to this many pole pairs less one).
  double search_turns = 12;
  // A runaway: the rotor faster than this many times the sweep speed.
  double runaway_factor = 4.0;
  // The rotor may be this far (electrical turns) from where the command puts it.
  double follow_tolerance_turns = 0.6;
  // The closed-loop check's hold: the encoder's angle within this of the commanded one.
  double check_bound_deg = 10.0;
  std::chrono::milliseconds period = timing::kCommissionPeriod;
  std::optional<CheckFile> check_file;  // --check: only the closed-loop check, with this file
  // -o: a HAL fragment is wanted. Refused before anything moves where none could be written
  // (no Halls, or --check, whose setup is the file checked).
  bool hal_fragment = false;
  // tune-axis: identify the mechanics (with check_file's commutation) instead of the check.
  std::optional<AxisIdentification> identify;
};

struct Preflight {
  eth::EthTarget target;
  std::string card;   // "8I20 unit 0x... firmware ..."
  std::string board;  // the Ethernet card's name: "7I96S", "7I92T"
  double max_current_a = 0;
  double bus_v = 0;
  std::uint16_t fault = 0;
  std::int64_t kqp = 0, kqi = 0;  // the current loop's gains (card counts): tune-axis's correction
  std::string note;
};

struct CommissionPlan {
  Preflight preflight;
  double current_a = 0;
  double check_current_a = 0;
  double align_s = 0, ramp_s = 0, sweep_turns = 0, turns_per_s = 0;
  double estimated_s = 0;
  // The most the rotor may turn from where it starts, in electrical turns (a mechanical
  // turn is pole-pairs electrical turns, so never more mechanical turns than this).
  double max_electrical_turns = 0;
  std::optional<double> max_mechanical_turns;  // when the pole pairs are known
  double runaway_turns_per_s = 0;              // electrical
  // The forward sweep goes on until the index has passed this often (twice unless the counts
  // per turn and the pole pairs are both given: the distance gives or checks the counts per
  // turn), up to search_turns electrical turns.
  int index_passes = 1;
  double search_turns = 0;
  double time_limit_s = 0;
  // --check: the file's setup with the options merged in; the run is only the closed-loop check.
  std::optional<BldcSetup> check;
  // tune-axis: the move within the window after the index search, with the check's setup.
  std::optional<AxisIdentification> identify;
  double identify_peak_turns_per_s = 0;  // the move's top speed, motor turns per second
  // The plan as lines for the user.
  std::vector<std::string> lines() const;
};

// Read-only. Throws UsageError (not an Ethernet target, bad options), Error kind Refused
// (bus voltage, latched faults, a running host, no encoder), or the link's errors. The
// session's card is dropped again before returning (the port is left stopped).
CommissionPlan prepare_commission(Session& session, const CommissionOptions& options);

enum class StopReason {
  Completed,     // swept, analysed and (where possible) checked
  CouldNotTell,  // swept, but the analysis could not tell every value (problems say why)
  CheckFailed,   // the closed-loop check did not pass
  Stall,
  Runaway,
  TravelLimit,
  NotFollowing,  // the rotor did not move as the plan said
  TimeLimit,
  Fault,      // the 8I20 latched a fault
  OtherHost,  // another host started talking to the card
  Signal,     // Ctrl-C, SIGTERM, SIGHUP (SIGPIPE: the app's output went away)
  LinkLost,   // the card stopped answering
  Error,      // anything else
};
std::string_view stop_reason_name(StopReason reason);

struct DirectionCheck {
  int torque_sign = 0;                // +1 forward command, -1 backward
  double moved_electrical_turns = 0;  // signed, forward positive
  bool passed = false;
};

struct ClosedLoopCheck {
  std::vector<DirectionCheck> directions;
  std::vector<double> hold_errors_deg;  // encoder angle minus commanded, at each hold
  double bound_deg = 0;
  std::size_t hall_samples = 0, hall_mismatches = 0;  // codes off the pattern's sector
  bool passed = false;
  std::string how;
};

struct CommissionReport {
  CommissionPlan plan;
  StopReason stop = StopReason::Error;
  std::string message;  // what happened, one line
  std::optional<commission::CommutationResult> result;
  std::optional<commission::BldcSettings> bldc;
  std::optional<ClosedLoopCheck> check;
  std::optional<unsigned> encoder_instance;
  std::vector<std::string> hall_pins;  // Hall 1, 2, 3
  std::size_t samples = 0;             // the drive cycles recorded, however far the run got
  double elapsed_s = 0;
  eth::DoitStats doit;
  bool current_zeroed = false;  // QSETPOINT 0 sent and the port stopped, confirmed
  std::string zero_note;        // why not, when not
  std::vector<std::string> notes;
  std::vector<commission::Sample> recorded;  // the sweep's samples (tests, --verbose)
  // tune-axis: what the move identified (at the motor shaft), and how far it went from where
  // it started (motor turns).
  std::optional<mechanics::Mechanics> mechanics;
  std::vector<mechanics::MotionSample> motion;  // the move as recorded: time, shaft angle, torque
  // The fit's windows with the torque the fitted mechanics give, before the current loop's
  // share is taken out of the inertia (what --svg draws beside the record).
  std::vector<mechanics::FitWindow> fit;
  double widest_turns = 0;

  Outcome outcome() const;
};

// Progress for the user while the motor moves ("aligning", "sweeping forward", ...).
using CommissionProgress = std::function<void(const std::string& phase)>;

// Drives the motor per the plan and returns the report; never throws for what happens on
// the way (that is the report), only UsageError for options the plan did not check.
CommissionReport run_commission(Session& session, const CommissionPlan& plan,
                                const CommissionOptions& options, const CommissionProgress& progress = {});

// A HAL fragment for today's LinuxCNC (hostmot2 + bldc) with what the report found: bldc
// with the cfg letters the motor has (qhi, qh), pattern, poles, scale, encoder-offset; the
// encoder's rawcounts (and index-enable), the Hall inputs, rotor-angle into the 8I20's
// angle and bldc's out into its current (amps). Throws Error (Refused) naming what is
// missing when the report cannot make a working setup (no Halls: bldc's q modes without h
// align the rotor through bldc's own A/B/C outputs, which an 8I20 does not take).
std::string commission_hal_fragment(const CommissionReport& report);

// bldc's values of an existing HAL file for the 8I20 on `channel` (the file's only bldc
// instance, or the one wired to that channel), and the encoder, Hall inputs and amp the file
// wires into it. Throws UsageError naming what is missing or wired to another channel.
BldcSetup read_bldc_setup(const std::string& hal_text, const std::string& file, unsigned channel);
// The setup with --encoder and --halls merged in; throws UsageError where they contradict the
// file, or when no encoder is known.
BldcSetup merge_check_options(BldcSetup setup, const CommissionOptions& options, const std::string& file);

}  // namespace i20::ops
