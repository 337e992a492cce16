// SPDX-License-Identifier: GPL-2.0-or-later
// i20 commission: find an 8I20 axis's commutation over Ethernet, check it in closed loop and
// write bldc's setup. Parses options, prints the plan and asks, renders the report: every
// decision is lib/ops/commission's.
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <numbers>
#include <sstream>
#include <type_traits>
#include <variant>

#include "commission/format.hpp"
#include "context.hpp"
#include "motor/units.hpp"
#include "ops/commission/commission.hpp"
#include "output_file.hpp"
#include "profile/strip_chart.hpp"

namespace i20::cli {
namespace {

using commission::fixed;

struct Args {
  ops::CommissionOptions o;
  std::optional<int> poles;
  std::string halls;
  std::string out;
  std::string check;
  bool overwrite = false;
  bool yes = false;
  bool yaml = false;
};

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');) out.push_back(part);
  return out;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw UsageError("--check " + path + ": cannot read the file");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

template <class T>
void finding(app::Json& findings, const char* key, const std::optional<commission::Finding<T>>& f) {
  if (!f) return;
  findings.set(
      key, app::Json::object().set("value", f->value).set("uncertainty", f->uncertainty).set("how", f->how));
}

template <class T>
app::Json array_of(const std::vector<T>& items) {
  auto j = app::Json::array();
  for (const auto& item : items) j.push(item);
  return j;
}

// The report as one typed tree: --json prints it, --yaml writes the same tree as YAML.
app::Json report_json(const ops::CommissionReport& r) {
  auto j = app::Json::object();
  j.set("target", r.plan.preflight.target.url());
  j.set("stop", std::string(ops::stop_reason_name(r.stop)));
  j.set("message", r.message);
  j.set("current_zeroed", r.current_zeroed);
  if (!r.zero_note.empty()) j.set("zero_note", r.zero_note);
  if (r.encoder_instance) j.set("encoder", *r.encoder_instance);
  j.set("hall_inputs", array_of(r.hall_pins));
  if (r.bldc) {
    auto b = app::Json::object();
    if (r.bldc->pattern) b.set("pattern", *r.bldc->pattern);
    if (r.bldc->poles) b.set("poles", *r.bldc->poles);
    if (r.bldc->scale) b.set("scale", *r.bldc->scale);
    if (r.bldc->encoder_offset) b.set("encoder-offset", *r.bldc->encoder_offset);
    b.set("missing", array_of(r.bldc->missing));
    j.set("bldc", std::move(b));
  }
  if (r.result) {
    const auto& f = *r.result;
    auto findings = app::Json::object();
    finding(findings, "encoder_direction", f.encoder_direction);
    finding(findings, "counts_per_electrical_turn", f.counts_per_electrical_turn);
    finding(findings, "pole_pairs", f.pole_pairs);
    finding(findings, "counts_per_turn", f.counts_per_turn);
    finding(findings, "index_electrical_angle_deg", f.index_electrical_angle_deg);
    finding(findings, "encoder_offset_counts", f.encoder_offset_counts);
    finding(findings, "hall_pattern", f.hall.bldc_pattern);
    finding(findings, "friction_lag_deg", f.friction_lag_deg);
    j.set("findings", std::move(findings));
    auto problems = app::Json::array();
    for (const auto& p : f.problems) problems.push(p.message);
    j.set("problems", std::move(problems));
  }
  if (r.check) {
    auto moved = app::Json::array();
    for (const auto& d : r.check->directions) moved.push(d.moved_electrical_turns);
    j.set("check", app::Json::object()
                       .set("passed", r.check->passed)
                       .set("moved_electrical_turns", std::move(moved))
                       .set("hold_errors_deg", array_of(r.check->hold_errors_deg))
                       .set("bound_deg", r.check->bound_deg)
                       .set("how", r.check->how));
  }
  if (r.mechanics) {
    const auto& m = *r.mechanics;
    const auto estimate = [](const mechanics::Estimate& e) {
      return app::Json::object().set("value", e.value).set("sigma", e.sigma);
    };
    j.set("mechanics", app::Json::object()
                           .set("inertia_kgm2", estimate(m.inertia_kgm2))
                           .set("viscous_nm_per_rad_s", estimate(m.viscous_nm_per_rad_s))
                           .set("coulomb_nm", estimate(m.coulomb_nm))
                           .set("bias_nm", estimate(m.bias_nm))
                           .set("windows", m.windows)
                           .set("widest_turns", r.widest_turns));
  }
  j.set("notes", array_of(r.notes));
  j.set("samples", r.samples);
  j.set("elapsed_s", r.elapsed_s);
  j.set("doit_period_us", app::Json::object()
                              .set("p50", r.doit.percentile(50).count())
                              .set("p99", r.doit.percentile(99).count())
                              .set("worst", r.doit.worst().count())
                              .set("late", r.doit.late)
                              .set("missed", r.doit.missed));
  return j;
}

void emit_yaml(YAML::Emitter& y, const app::Json& j) {
  std::visit(
      [&y](const auto& v) {
        using V = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<V, std::nullptr_t>) {
          y << YAML::Null;
        } else if constexpr (std::is_same_v<V, app::Json::Array>) {
          y << YAML::BeginSeq;
          for (const auto& item : v) emit_yaml(y, item);
          y << YAML::EndSeq;
        } else if constexpr (std::is_same_v<V, app::Json::Object>) {
          y << YAML::BeginMap;
          for (const auto& [key, value] : v) {
            y << YAML::Key << key << YAML::Value;
            emit_yaml(y, value);
          }
          y << YAML::EndMap;
        } else {
          y << v;  // bool, integer, double, string
        }
      },
      j.value());
}

std::string report_yaml(const app::Json& report) {
  YAML::Emitter y;
  emit_yaml(y, report);
  return std::string(y.c_str()) + "\n";
}

// The report under the name of the command the user ran (commission or tune-axis).
void print_text(const ops::CommissionReport& r, const std::string& command) {
  std::cout << command << " " << r.plan.preflight.target.url() << ": " << r.message << "\n";
  if (r.bldc) {
    const auto& b = *r.bldc;
    if (b.pattern)
      std::cout << "  pattern         " << *b.pattern << "  (Hall inputs " << r.hall_pins[0] << ", "
                << r.hall_pins[1] << ", " << r.hall_pins[2] << ")\n";
    if (b.poles) std::cout << "  poles           " << *b.poles << "\n";
    if (b.scale)
      std::cout << "  scale           " << *b.scale << "  (encoder " << r.encoder_instance.value_or(0)
                << ")\n";
    if (b.encoder_offset) std::cout << "  encoder-offset  " << *b.encoder_offset << "\n";
    for (const auto& m : b.missing) std::cout << "  missing: " << m << "\n";
  }
  if (r.result) {
    const auto& f = *r.result;
    auto line = [](const char* what, const auto& opt, const char* unit) {
      if (opt)
        std::cout << "  " << what << ": " << opt->value << unit << " +- " << fixed(opt->uncertainty, 2)
                  << " (" << opt->how << ")\n";
    };
    line("encoder direction", f.encoder_direction, "");
    line("counts per electrical turn", f.counts_per_electrical_turn, "");
    line("pole pairs", f.pole_pairs, "");
    line("index electrical angle", f.index_electrical_angle_deg, " deg");
    for (const auto& p : f.problems) std::cout << "  could not tell: " << p.message << "\n";
    for (const auto& n : f.notes) std::cout << "  note: " << n << "\n";
  }
  if (r.mechanics) {
    const auto& m = *r.mechanics;
    const auto line = [](const char* what, const mechanics::Estimate& e, double scale, const char* unit) {
      std::cout << "  " << what << " " << e.value * scale << " +- " << e.sigma * scale << " " << unit << "\n";
    };
    line("inertia (total, at the motor)  ", m.inertia_kgm2, 1e4, "kg cm^2");
    line("viscous friction               ", m.viscous_nm_per_rad_s, 1e3, "mNm/(rad/s)");
    line("Coulomb friction               ", m.coulomb_nm, 1, "Nm");
    line("bias (+ opposes forward motion)", m.bias_nm, 1, "Nm");
    std::cout << "  fitted over " << m.windows << " windows; the move went +-" << fixed(r.widest_turns, 3)
              << " motor turns\n";
  }
  if (r.check)
    std::cout << "  closed-loop check " << (r.check->passed ? "passed" : "FAILED") << ": " << r.check->how
              << "\n";
  for (const auto& n : r.notes) std::cout << "  note: " << n << "\n";
  std::cout << "  " << r.samples << " samples in " << fixed(r.elapsed_s, 1) << " s; DOIT period p50 "
            << fixed(r.doit.percentile(50).count() / 1000.0, 1) << " ms, p99 "
            << fixed(r.doit.percentile(99).count() / 1000.0, 1) << " ms, worst "
            << fixed(r.doit.worst().count() / 1000.0, 1) << " ms\n";
  std::cout << "  " << (r.current_zeroed ? "current: QSETPOINT 0 sent and the port stopped" : r.zero_note)
            << "\n";
}

// How a moving command is run, in its words: `name` (the plan's and progress's prefix),
// what the question asks to do and whom to keep clear of.
struct MotionRun {
  const char* name;
  const char* action;
  const char* keep_clear_of;
  bool yes;
  bool yaml;
};

// The plan printed and asked for, the run, and its report rendered and recorded: what
// commission and tune-axis share.
ops::CommissionReport plan_ask_and_run(Context& ctx, const ops::CommissionOptions& options,
                                       const MotionRun& how) {
  auto& session = ctx.session();
  const auto plan = ops::prepare_commission(session, options);
  const std::string name = how.name;
  std::cerr << "i20 " << name << ": the plan\n";
  for (const auto& line : plan.lines()) std::cerr << "  " << line << "\n";
  if (!how.yes)
    ctx.require_confirmation(std::string(how.action) + " on " + plan.preflight.target.url() +
                                 " as planned? Keep clear of " + how.keep_clear_of,
                             name + " not confirmed; the motor was not driven (pass --yes in scripts)");
  const auto report = ops::run_commission(session, plan, options, [&name](const std::string& phase) {
    std::cerr << "i20 " << name << ": " << phase << "\n";
  });
  const auto tree = report_json(report);
  if (ctx.options.json)
    ctx.print_json(tree);
  else if (how.yaml)
    std::cout << report_yaml(tree);
  else
    print_text(report, name);
  ctx.record(report.outcome());
  if (!report.current_zeroed) std::cerr << "i20: card state: " << report.zero_note << "\n";
  return report;
}

void run_commission_command(Context& ctx, Args& a) {
  check_output_file(a.out, a.overwrite);
  if (a.poles) {
    if (*a.poles < 2 || *a.poles % 2 != 0)
      throw UsageError(std::string("--poles ") + std::to_string(*a.poles) +
                       ": an even number (poles, not pole pairs)");
    a.o.pole_pairs = *a.poles / 2;
  }
  if (!a.halls.empty()) a.o.halls = split_commas(a.halls);
  if (!a.check.empty()) a.o.check_file = ops::CheckFile{read_text(a.check), a.check};
  a.o.hal_fragment = !a.out.empty();
  const auto report =
      plan_ask_and_run(ctx, a.o, {"commission", "Drive the motor", "the axis", a.yes, a.yaml});
  if (a.out.empty()) return;
  if (report.outcome() != ops::Outcome::Done) {
    std::cerr << "i20: " << a.out << " not written: the commissioning did not complete\n";
    return;
  }
  write_file_atomically(a.out, ops::commission_hal_fragment(report), a.overwrite);
  std::cerr << "i20: wrote " << a.out << "\n";
}

// ------------------------------------------------------------------ tune-axis
struct TuneAxisArgs {
  ops::CommissionOptions o;
  std::string check, travel, lead, torque_constant, inertia_guess, friction_guess = "0Nm", csv, svg;
  bool yes = false, yaml = false, overwrite = false;
};

double quantity(motor::Quantity kind, const char* flag, const std::string& text) {
  try {
    return motor::parse_quantity(kind, text);
  } catch (const Error& e) {
    throw UsageError(std::string(flag) + ": " + e.what());
  }
}

// The window in motor turns: a length over --lead (a screw, a belt), or an angle (rotary).
double half_window_turns(const TuneAxisArgs& a) {
  if (a.lead.empty()) return quantity(motor::Quantity::Angle, "--travel", a.travel) / (4 * std::numbers::pi);
  const double lead = quantity(motor::Quantity::Length, "--lead", a.lead);
  if (!(lead > 0)) throw UsageError("--lead must be a positive length: the travel per motor turn, e.g. 5mm");
  return quantity(motor::Quantity::Length, "--travel", a.travel) / lead / 2;
}

std::string motion_csv(const ops::CommissionReport& r) {
  std::ostringstream out;
  out << "time_s,shaft_rad,torque_nm\n";
  for (const auto& s : r.motion) out << s.time_s << "," << s.position_rad << "," << s.torque_nm << "\n";
  return out.str();
}

// The move and the fit on one time axis: where the shaft went, and the torque in effect beside
// the torque the fitted mechanics give for each window's motion (gaps: windows the fit left
// out, where the shaft reversed or crept). Where the two torques part, the model does not
// describe the axis there.
profile::StripChart identification_chart(const ops::CommissionReport& r) {
  profile::StripChart chart{
      "i20 tune-axis on " + r.plan.preflight.target.url() + ": the move and the fit", {}, {}};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> turns, recorded, fitted(r.motion.size(), nan);
  const double start =
      r.motion.empty() ? 0.0 : r.motion.front().time_s;  // the card's timer: from the move's start
  std::size_t w = 0;
  for (std::size_t k = 0; k < r.motion.size(); ++k) {
    const auto& s = r.motion[k];
    chart.time_s.push_back(s.time_s - start);
    turns.push_back(s.position_rad / (2 * std::numbers::pi));
    recorded.push_back(s.torque_nm);
    while (w < r.fit.size() && r.fit[w].to_s <= s.time_s) ++w;
    if (w < r.fit.size() && r.fit[w].from_s <= s.time_s) fitted[k] = r.fit[w].fitted_nm;
  }
  chart.strips.push_back({"Shaft, from where the index was found", "motor turns", {{"position", turns}}});
  chart.strips.push_back(
      {"Torque", "Nm", {{"in effect", recorded}, {"the fit (each window's mean)", fitted}}});
  return chart;
}

void run_tune_axis_command(Context& ctx, TuneAxisArgs& a) {
  check_output_file(a.csv, a.overwrite);
  check_output_file(a.svg, a.overwrite);
  if (!a.svg.empty() && a.svg == a.csv) throw UsageError("--svg and --csv name the same file");
  a.o.check_file = ops::CheckFile{read_text(a.check), a.check};
  a.o.identify = ops::AxisIdentification{
      .half_window_turns = half_window_turns(a),
      .duration_s = a.o.identify ? a.o.identify->duration_s : 8.0,
      .torque_constant_nm_per_a =
          quantity(motor::Quantity::TorqueConstant, "--torque-constant", a.torque_constant),
      .inertia_guess_kgm2 = quantity(motor::Quantity::Inertia, "--inertia-guess", a.inertia_guess),
      .friction_guess_nm = quantity(motor::Quantity::Torque, "--friction-guess", a.friction_guess)};
  const auto report = plan_ask_and_run(ctx, a.o, {"tune-axis", "Move the axis", "it", a.yes, a.yaml});
  // A run that stopped before the move recorded nothing to write: said, not left silent.
  const bool moved = report.motion.size() >= 2;
  for (const auto* file : {&a.csv, &a.svg})
    if (!file->empty() && !moved) std::cerr << "i20: " << *file << " not written: the run recorded no move\n";
  if (!a.csv.empty() && moved) {
    write_file_atomically(a.csv, motion_csv(report), a.overwrite);
    std::cerr << "i20: wrote " << a.csv << "\n";
  }
  if (!a.svg.empty() && moved) {
    write_file_atomically(a.svg, profile::strip_chart_svg(identification_chart(report)), a.overwrite);
    std::cerr << "i20: drew the move" << (report.fit.empty() ? "" : " and the fit") << " in " << a.svg
              << "\n";
  }
  if (report.mechanics && report.outcome() == ops::Outcome::Done && !ctx.options.json)
    std::cerr << "i20: next, the gains: i20 pid --inertia " << report.mechanics->inertia_kgm2.value << "kgm^2"
              << " --viscous " << report.mechanics->viscous_nm_per_rad_s.value << "Nm/(rad/s) --coulomb "
              << report.mechanics->coulomb_nm.value << "Nm --bias " << report.mechanics->bias_nm.value
              << "Nm --torque-constant " << a.torque_constant
              << (a.lead.empty() ? std::string(" --lead 360deg --units deg") : " --lead " + a.lead)
              << " --max-current " << fixed(report.plan.preflight.max_current_a, 2) << "A\n";
}

void register_tune_axis_command(CLI::App& app, Context& ctx) {
  auto a = std::make_shared<TuneAxisArgs>();
  a->o.identify = ops::AxisIdentification{};
  auto* cmd = app.add_subcommand(
      "tune-axis",
      "Identify an axis's mechanics over Ethernet (--eth IP or eth://IP/chN): the total inertia at the "
      "motor, "
      "its viscous and Coulomb friction and a constant bias (a vertical axis's weight), each with its "
      "uncertainty, from a gentle back-and-forth move within the travel window you give. It commutates with "
      "the setup of --check FILE.hal (what i20 commission -o wrote: its index and encoder-offset), turning "
      "forward up to one motor turn to find the index, then moves under a position loop of its own within "
      "--travel about that place. The same preflight, plan-and-ask (--yes in scripts) and stops as i20 "
      "commission: a runaway, the travel or time limit, a latched fault, another host or Ctrl-C end it with "
      "QSETPOINT 0 and the port stopped, and the 8I20's 40 ms watchdog disables it should this program die. "
      "Afterwards the current is 0: hold a vertical axis with its brake or a counterweight. The values feed "
      "i20 pid (it prints the command). Exit codes as i20 commission's (3: the move could not identify "
      "them). "
      "docs/axis-tuning.md says how and how well.");
  cmd->add_option("--check", a->check,
                  "The axis's commutation: a HAL file with bldc cfg qi/qhi (i20 commission -o)")
      ->required();
  cmd->add_option(
         "--travel", a->travel,
         "The travel window the axis may use, in all: a length with --lead (10mm), or an angle for a "
         "rotary axis without it (720deg); centred where the index is found")
      ->required();
  cmd->add_option("--lead", a->lead, "Travel per motor turn (a 5 mm screw direct: 5mm)");
  cmd->add_option("--torque-constant", a->torque_constant, "The motor's torque constant (0.45Nm/A)")
      ->required();
  cmd->add_option("--inertia-guess", a->inertia_guess,
                  "A guess of the total inertia at the motor (the rotor's from its datasheet will do, e.g. "
                  "0.6kgcm^2): it sets the move's loop gain only")
      ->required();
  cmd->add_option("--friction-guess", a->friction_guess,
                  "A guess of the friction torque (default 0Nm): stiffens the loop so friction holds it back "
                  "little");
  cmd->add_option("--duration", a->o.identify->duration_s, "Seconds of back-and-forth (default 8)");
  cmd->add_option("--current", a->o.current_amps,
                  "The most current the move and the index search may use, in amps (default 20% of "
                  "MAXCURRENT; never above it)");
  cmd->add_option("--time-limit", a->o.time_limit_s, "Stop after this many seconds in all (default 60)");
  cmd->add_option("--csv", a->csv, "Write the move as recorded: time, shaft angle (rad), torque (Nm)");
  cmd->add_option("--svg", a->svg,
                  "Draw the move and the fit (shaft angle; the torque in effect beside the torque the "
                  "identified mechanics give) as an SVG, for a browser");
  cmd->add_flag("--overwrite", a->overwrite, "Replace an existing --csv or --svg file");
  cmd->add_flag("--yes,-y", a->yes, "Do not ask before driving the motor (scripts)");
  cmd->add_flag("--yaml", a->yaml, "The report as YAML");
  cmd->callback([&ctx, a] { run_tune_axis_command(ctx, *a); });
}

}  // namespace

void register_commission_command(CLI::App& app, Context& ctx) {
  register_tune_axis_command(app, ctx);
  auto a = std::make_shared<Args>();
  auto* cmd = app.add_subcommand(
      "commission",
      "Find an 8I20 axis's commutation and check it: over Ethernet (--eth IP or eth://IP/chN; a 7I96S or "
      "7I92T), "
      "with the motor free to turn (brake released, nothing it can hit within a few turns). A read-only "
      "preflight "
      "first (card, no other host running it, bus 24..385 V, no latched faults, an encoder); then the plan "
      "is "
      "printed and asked for (--yes in scripts). The 8I20 holds the rotor with a ramped current (by default "
      "20% "
      "of MAXCURRENT), sweeps its electrical angle slowly several turns forward and back while the encoder, "
      "its "
      "index and the Hall inputs are recorded, and the analysis finds the encoder direction and counts, the "
      "pole "
      "pairs, bldc's Hall pattern and the index's encoder-offset. A closed-loop check with those values at a "
      "smaller current must turn the motor each way as commanded. It stops at once on a runaway, a stall (is "
      "the brake released? the motor connected?), a rotor that does not follow, the travel or time limit, a "
      "latched fault, another host, or Ctrl-C; every stop ends with QSETPOINT 0 and the port stopped, and "
      "the "
      "8I20's 40 ms watchdog disables it should this program die. Exit 0: found and checked; 1: the card not "
      "reached or the link lost; 2: bad options or not confirmed (nothing driven); 3: stopped by a safety "
      "rule "
      "or not every value could be told (the report says why); 4: the stop was not confirmed (the watchdog "
      "turns the output off); 6: the report or -o FILE could not be written; 130: a signal. -o FILE.hal "
      "writes "
      "bldc's setup for LinuxCNC; --check FILE.hal re-runs only the closed-loop check with an existing "
      "setup. "
      "docs/commissioning.md walks through a real axis.");
  cmd->add_option(
      "--encoder", a->o.encoder,
      "hostmot2 encoder instance of the axis (default: the one that moves; with --check: the one the "
      "file nets into bldc's rawcounts)");
  cmd->add_option(
      "--halls", a->halls,
      "The Hall inputs, Hall 1,2,3, as hostmot2 names them after the board: gpio.010.in,gpio.011.in,"
      "gpio.012.in or inm.00.input-00,... (default: the three inputs that change)");
  cmd->add_flag("--no-halls", a->o.no_halls, "The motor has no Hall sensors");
  cmd->add_option("--poles", a->poles, "Motor poles when known (bldc's poles: twice the pole pairs)");
  cmd->add_option("--counts-per-rev", a->o.counts_per_turn,
                  "Encoder counts per motor turn when known (4 x lines)");
  cmd->add_option("--current", a->o.current_amps,
                  "Sweep current in amps (default 20% of MAXCURRENT; never above it)");
  cmd->add_option("--sweep-turns", a->o.sweep_turns, "Electrical turns each way (default 3)");
  cmd->add_option("--turns-per-second", a->o.turns_per_s,
                  "Sweep speed in electrical turns per second (default 1.5)");
  cmd->add_option("--time-limit", a->o.time_limit_s, "Stop after this many seconds in all (default 60)");
  cmd->add_flag("--yes,-y", a->yes, "Do not ask before driving the motor (scripts)");
  cmd->add_flag("--yaml", a->yaml, "The report as YAML");
  cmd->add_option("-o,--output", a->out,
                  "Write bldc's setup as a HAL fragment (hostmot2 + bldc) when all is found and checked");
  cmd->add_flag("--overwrite", a->overwrite, "Replace an existing -o file");
  cmd->add_option("--check", a->check,
                  "Only the closed-loop check, with what this HAL file sets up for --channel's 8I20: bldc's "
                  "values and cfg, "
                  "the encoder on its rawcounts, the inputs on its hall1..3");
  cmd->callback([&ctx, a] { run_commission_command(ctx, *a); });
}

}  // namespace i20::cli
