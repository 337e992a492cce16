// SPDX-License-Identifier: GPL-2.0-or-later
// i20 pid: LinuxCNC pid gains for an 8I20 axis, designed to stated margins from its mechanics
// (ops/axis_pid.hpp), printed or written as the [JOINT_n] lines `i20 hal`'s file reads. Needs
// no card.
#include "cmd_pid.hpp"

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <numbers>

#include "motor/error.hpp"
#include "motor/loader.hpp"
#include "motor/units.hpp"
#include "ops/axis_pid.hpp"
#include "output_file.hpp"
#include "profile/quantity.hpp"
#include "profile/strip_chart.hpp"

namespace i20::cli {
namespace {

struct PidCliOptions {
  std::string motor_file;
  std::string inertia, viscous, coulomb, bias, torque_constant, lead;  // "" where not given
  std::string units = "mm";
  std::string max_current, resonance, rotor_inertia;
  std::optional<double> damping_ratio;
  double servo_period_ns = 1e6;
  std::optional<double> delay_ns;
  double phase_margin = 45, gain_margin = 8;
  int joint = 0;
  std::string out, svg, csv;
  double move_distance = 10, move_speed = 20, move_accel = 500;
  bool overwrite = false;
  bool notch = false;
};

double motor_quantity(motor::Quantity kind, const std::string& flag, const std::string& text) {
  try {
    return motor::parse_quantity(kind, text);
  } catch (const motor::MotorError& e) {
    throw UsageError(flag + ": " + e.what());
  }
}

double profile_quantity(profile::Quantity kind, const std::string& flag, const std::string& text) {
  std::string why;
  const auto value = profile::parse_quantity(kind, text, why);
  if (!value) throw UsageError(flag + ": " + why);
  return *value;
}

// Machine units per metre of travel, or per radian of a rotary axis (deg).
double units_per_si(const std::string& units) {
  if (units == "mm") return 1000;
  if (units == "m") return 1;
  if (units == "in") return 1 / 0.0254;
  if (units == "deg") return 180 / std::numbers::pi;
  throw UsageError("--units: '" + units + "' is not mm, m, in or deg (the units of the INI's positions)");
}

// --lead: travel per motor turn, a length for mm/m/in, an angle for a rotary axis in deg.
double lead_si(const PidCliOptions& o) {
  if (o.lead.empty())
    throw UsageError("--lead is needed without --motor: the travel per motor turn, e.g. 5mm");
  return motor_quantity(o.units == "deg" ? motor::Quantity::Angle : motor::Quantity::Length, "--lead",
                        o.lead);
}

mechanics::AxisModel axis_from_flags(const PidCliOptions& o, double max_current) {
  using Q = motor::Quantity;
  if (o.inertia.empty() || o.torque_constant.empty())
    throw UsageError(
        "give --motor FILE, or --inertia, --torque-constant and --lead (and the friction and bias "
        "you measured)");
  mechanics::AxisModel a;
  a.inertia_kgm2 = motor_quantity(Q::Inertia, "--inertia", o.inertia);
  // Friction and bias not given are none.
  a.viscous_nm_per_rad_s = o.viscous.empty() ? 0 : motor_quantity(Q::Viscous, "--viscous", o.viscous);
  a.coulomb_nm = o.coulomb.empty() ? 0 : motor_quantity(Q::Torque, "--coulomb", o.coulomb);
  a.bias_nm = o.bias.empty() ? 0 : motor_quantity(Q::Torque, "--bias", o.bias);
  a.torque_constant_nm_per_a = motor_quantity(Q::TorqueConstant, "--torque-constant", o.torque_constant);
  a.units_per_rad = lead_si(o) * units_per_si(o.units) / (2 * std::numbers::pi);
  a.max_current_a = max_current;
  return a;
}

// The simulated move as strips: position (command and encoder), following error, current.
profile::StripChart move_chart(const mechanics::MoveTrace& trace, const std::string& units,
                               const std::string& title) {
  // The error in a thousandth of the unit (um for mm, thou for in, mdeg for deg), um for m.
  const double error_scale = units == "m" ? 1e6 : 1e3;
  const std::string error_unit = units == "mm" || units == "m" ? "um" : units == "in" ? "thou" : "mdeg";
  profile::StripChart chart{title,
                            {},
                            {{"Position", units, {{"command", {}}, {"encoder", {}}}},
                             {"Following error", error_unit, {{"command - encoder", {}}}},
                             {"Current", "A", {{"pid output", {}}}}}};
  for (const auto& p : trace.points) {
    chart.time_s.push_back(p.time_s);
    chart.strips[0].series[0].values.push_back(p.command);
    chart.strips[0].series[1].values.push_back(p.position);
    chart.strips[1].series[0].values.push_back(p.error * error_scale);
    chart.strips[2].series[0].values.push_back(p.current_a);
  }
  return chart;
}

void run_pid(const PidCliOptions& o) {
  if (o.max_current.empty())
    throw UsageError("--max-current is needed: the 8I20's MAXCURRENT, pid's maxoutput");
  const double max_current = profile_quantity(profile::Quantity::Current, "--max-current", o.max_current);
  ops::AxisPidRequest request;
  if (!o.motor_file.empty()) {
    for (const auto* flag : {&o.inertia, &o.torque_constant, &o.lead, &o.viscous, &o.coulomb, &o.bias})
      if (!flag->empty())
        throw UsageError(
            "--motor gives the mechanics: leave out --inertia, --viscous, --coulomb, --bias, "
            "--torque-constant "
            "and --lead");
    if (o.units == "deg")
      throw UsageError(
          "--units deg is for a rotary axis given by --lead in degrees; a motor file's lead is a length");
    const double units = units_per_si(o.units);
    try {
      request.axis = ops::axis_from_motor(motor::load_motor_file(o.motor_file), units, max_current);
    } catch (const motor::MotorError& e) {
      throw UsageError(e.what());  // it names the file
    } catch (const UsageError& e) {
      throw UsageError(o.motor_file + ": " + e.what());
    }
  } else {
    request.axis = axis_from_flags(o, max_current);
  }
  if (!o.resonance.empty())
    request.axis.resonance_hz = profile_quantity(profile::Quantity::Frequency, "--resonance", o.resonance);
  if (!o.rotor_inertia.empty()) {
    if (o.resonance.empty())
      throw UsageError("--rotor-inertia models the two masses of a --resonance: give both");
    request.axis.rotor_inertia_kgm2 =
        motor_quantity(motor::Quantity::Inertia, "--rotor-inertia", o.rotor_inertia);
  }
  if (o.damping_ratio) request.axis.coupling_damping_ratio = *o.damping_ratio;
  request.timing.servo_period_s = o.servo_period_ns * 1e-9;
  request.timing.delay_s = o.delay_ns.value_or(o.servo_period_ns) * 1e-9;
  request.margins = {o.phase_margin, o.gain_margin};
  request.joint = o.joint;
  request.notch = o.notch ? mechanics::NotchUse::WhereItHelps : mechanics::NotchUse::Never;
  if (!o.svg.empty() || !o.csv.empty()) {
    if (o.motor_file.empty())
      throw UsageError("--svg and --csv simulate the move on a motor file's model: give --motor FILE");
    request.truth = motor::load_motor_file(o.motor_file);
    request.move = mechanics::MoveProfile{o.move_distance, o.move_speed, o.move_accel, 0.5};
  }
  for (const auto* path : {&o.out, &o.svg, &o.csv})
    if (!path->empty()) check_output_file(*path, o.overwrite);
  const auto result = ops::design_axis_pid(request);
  if (const auto& n = result.gains.notch)
    std::fprintf(stderr,
                 "the loop has a notch at %.1f Hz (q %.2f) after pid: the HAL must run it (i20 hal --notch), "
                 "or LinuxCNC runs a loop these gains were not designed for\n",
                 n->frequency_hz, n->q);
  else if (o.notch)
    std::fprintf(stderr, "no notch: on this axis it would not let the loop cross over higher\n");
  if (result.trace) {
    char title[160];
    std::snprintf(title, sizeof title, "Joint %d: %g %s out and back at %g %s/s (simulated, %s)", o.joint,
                  o.move_distance, o.units.c_str(), o.move_speed, o.units.c_str(), o.motor_file.c_str());
    const auto chart = move_chart(*result.trace, o.units, title);
    if (!o.svg.empty()) write_file_atomically(o.svg, profile::strip_chart_svg(chart), o.overwrite);
    if (!o.csv.empty()) write_file_atomically(o.csv, profile::strip_chart_csv(chart), o.overwrite);
    std::fprintf(stderr, "simulated move: following error peak %g %s, RMS %g %s, %g %s at rest%s%s%s%s\n",
                 result.trace->peak_error, o.units.c_str(), result.trace->rms_error, o.units.c_str(),
                 result.trace->rest_error, o.units.c_str(), o.svg.empty() ? "" : "; drawn in ", o.svg.c_str(),
                 o.csv.empty() ? "" : "; samples in ", o.csv.c_str());
  }
  if (o.out.empty()) {
    std::cout << result.ini << std::flush;
    return;
  }
  write_file_atomically(o.out, result.ini, o.overwrite);
  std::cout << "[JOINT_" << o.joint << "] gains written to " << o.out << ": crossover "
            << static_cast<int>(result.gains.crossover_hz * 10 + 0.5) / 10.0 << " Hz, phase margin "
            << static_cast<int>(result.gains.phase_margin_deg + 0.5) << " degrees, gain margin "
            << static_cast<int>(result.gains.gain_margin_db * 10 + 0.5) / 10.0
            << " dB. Merge them into your INI.\n";
}

}  // namespace

void register_pid_command(CLI::App& app, Context&) {
  auto o = std::make_shared<PidCliOptions>();
  auto* cmd = app.add_subcommand("pid",
                                 "LinuxCNC pid gains for an 8I20 axis, designed from its mechanics to a "
                                 "stated phase and gain margin (not "
                                 "guessed, not Ziegler-Nichols): P, I, D, FF1, FF2 and BIAS as the [JOINT_n] "
                                 "lines `i20 hal`'s file reads, "
                                 "for the pid whose output is the 8I20's current in amps. The mechanics come "
                                 "from --motor FILE (a motor file "
                                 "with its machine: the virtual axis's truth, to rehearse) or from the "
                                 "values you measured: total inertia "
                                 "at the motor, friction, the bias a vertical axis needs, the torque "
                                 "constant and the lead. Needs no card");
  cmd->add_option("--motor", o->motor_file, "Motor file with its machine (motors/README.md): the mechanics")
      ->type_name("FILE");
  cmd->add_option("--inertia", o->inertia,
                  "Total inertia at the motor shaft, rotor and load, e.g. 1.1kgcm^2");
  cmd->add_option("--viscous", o->viscous, "Viscous friction at the motor, e.g. 0.05mNm/(rad/s) (default 0)");
  cmd->add_option("--coulomb", o->coulomb,
                  "Coulomb friction at the motor, e.g. 0.02Nm (default 0: the I term takes it)");
  cmd->add_option(
      "--bias", o->bias,
      "Constant torque against forward motion, a vertical axis's weight, e.g. 0.31Nm (default 0)");
  cmd->add_option("--torque-constant", o->torque_constant, "Motor torque per amp, e.g. 0.45Nm/A");
  cmd->add_option("--lead", o->lead,
                  "Machine travel per motor turn in --units, e.g. 5mm (a rotary axis: 36deg)");
  cmd->add_option("--units", o->units, "The INI's machine units: mm (default), m, in or deg");
  cmd->add_option("--max-current", o->max_current, "The 8I20's MAXCURRENT, pid's maxoutput, e.g. 10A");
  cmd->add_option(
      "--resonance", o->resonance,
      "The axis's first mechanical resonance, if known, e.g. 180Hz: the loop stays a fifth below it");
  cmd->add_option(
      "--rotor-inertia", o->rotor_inertia,
      "With --resonance: the motor's own rotor inertia (its data sheet), e.g. 0.6kgcm^2. The loop is then "
      "designed on two masses, the rotor and the rest behind the ringing coupling, and keeps its margins "
      "at the resonance's peak too (a motor file with a machine stiffness gives both)");
  cmd->add_flag(
      "--notch", o->notch,
      "With a two-mass model (--rotor-inertia, or a motor file's stiffness): allow a notch at the resonance "
      "after pid, where it lets the loop cross over higher; the margins then hold with the resonance "
      "anywhere within +-10% of the figure. Adds NOTCH_N0..NOTCH_D2 to the [JOINT_n] lines: the HAL must "
      "run it (i20 hal --notch), or LinuxCNC runs another loop than the one designed");
  cmd->add_option("--damping-ratio", o->damping_ratio,
                  "The coupling's damping ratio, if measured (default 0.02: a sharp peak, the safe side)")
      ->check(CLI::Range(0.001, 1.0));
  cmd->add_option("--servo-period", o->servo_period_ns, "[EMCMOT]SERVO_PERIOD in ns (default 1000000)")
      ->check(CLI::Range(50000.0, 10000000.0));
  cmd->add_option("--delay", o->delay_ns,
                  "Feedback read to current written, in ns (default: the whole servo period, the safe side)")
      ->check(CLI::Range(0.0, 10000000.0));
  cmd->add_option("--phase-margin", o->phase_margin, "Phase margin in degrees (default 45)");
  cmd->add_option("--gain-margin", o->gain_margin, "Gain margin in dB (default 8)");
  cmd->add_option("--joint", o->joint, "The joint's number in [JOINT_n] (default 0)");
  cmd->add_option("--out,-o", o->out, "Write the [JOINT_n] lines to FILE instead of printing them");
  cmd->add_option(
         "--svg", o->svg,
         "With --motor: simulate a move under LinuxCNC's pid with these gains on the motor file's model "
         "and draw position, following error and current on one time axis (SVG)")
      ->type_name("FILE");
  cmd->add_option("--csv", o->csv,
                  "With --motor: the simulated move's samples as CSV, one row per servo period")
      ->type_name("FILE");
  cmd->add_option("--move-distance", o->move_distance,
                  "The simulated move's length in --units (default 10), out and back");
  cmd->add_option("--move-speed", o->move_speed, "Its speed in --units per s (default 20)");
  cmd->add_option("--move-accel", o->move_accel, "Its acceleration in --units per s^2 (default 500)");
  cmd->add_flag("--overwrite", o->overwrite, "Replace --out, --svg and --csv if they exist");
  cmd->footer(
      "Exit 0 with the gains, 2 for a bad value (nothing written), 1 when no loop keeps the margins at this "
      "servo "
      "period. Margins are computed on a model of the loop (the period's hold, a delay, the 8I20's current "
      "loop), "
      "not measured on the machine: start with following-error limits that would stop a bad loop. Examples:\n"
      "  i20 pid --motor motors/vertical-screw-axis.yaml --max-current 10A --svg move.svg\n"
      "  i20 pid --inertia 1.1kgcm^2 --coulomb 0.02Nm --bias 0.31Nm --torque-constant 0.45Nm/A --lead 5mm "
      "\\\n"
      "          --max-current 10A --resonance 180Hz --joint 2 -o joint2.ini");
  cmd->callback([o] { run_pid(*o); });
}

}  // namespace i20::cli
