// SPDX-License-Identifier: GPL-2.0-or-later
// i20 tune: KQP/KDP/KQI/KDI for a motor, what they mean (a simulated current step as an SVG
// and a terminal plot), and a tuning profile ready to validate and apply. Needs no card.
#include "cmd_tune.hpp"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numbers>

#include "change_render.hpp"
#include "context.hpp"
#include "output_file.hpp"
#include "profile/error.hpp"
#include "profile/loader.hpp"
#include "profile/plot_scale.hpp"
#include "profile/quantity.hpp"
#include "profile/step_response.hpp"
#include "profile/svg_plot.hpp"
#include "profile/text_plot.hpp"
#include "profile/tune.hpp"
#include "profile/tuning_profile.hpp"
#include "profile/validate.hpp"
#include "profile/writer.hpp"

namespace i20::cli {
namespace {

namespace render = app::render;

using profile::Quantity;

struct TuneCliOptions {
  std::string from;  // a motor profile whose metadata gives what the flags do not
  std::string resistance, inductance, max_current, bus, bandwidth;
  std::string svg, out, name;
  bool ascii = false;
  bool line_to_line = false;  // -R and -L are the data sheet's line-to-line values
  bool force = false;         // write gains the model calls unstable
  bool overwrite = false;     // replace an existing --out or --svg file
};

// Where the request's values came from, for the output and the profile written.
struct Basis {
  bool resistance_line_to_line = false;
  bool inductance_line_to_line = false;
  std::string max_current_from;  // "" (flag or profile setting), or why another value was used
};

std::string format(const char* pattern, double value) {
  char buf[64];
  std::snprintf(buf, sizeof buf, pattern, value);
  return buf;
}

double quantity(Quantity kind, const std::string& flag, const std::string& text) {
  std::string why;
  const auto value = profile::parse_quantity(kind, text, why);
  if (!value) throw UsageError(flag + ": " + why);
  return *value;
}

// "500Hz", "500 Hz" or "0.5kHz": the unit is required, as for every other quantity.
double bandwidth_hz(const std::string& text) {
  return quantity(Quantity::Frequency, "--bandwidth", text);
}

// The motor profile's metadata and MAXCURRENT, where it has them. Without a MAXCURRENT
// setting the motor's peak current is what the manual advises MAXCURRENT be set to, within
// the card's own limit.
void fill_from_profile(const profile::Profile& p, const params::ParamDb& db, profile::TuneRequest& r,
                       Basis& basis) {
  r.motor.resistance_ohm = p.motor.phase_resistance_ohm.value_or(0);
  r.motor.inductance_h = p.motor.phase_inductance_h.value_or(0);
  basis.resistance_line_to_line = p.motor.line_to_line_resistance_ohm.has_value();
  basis.inductance_line_to_line = p.motor.line_to_line_inductance_h.has_value();
  r.bus_voltage_v = p.supply.bus_voltage_v.value_or(0);
  for (const auto& s : p.settings) {
    const params::Param& param = db.get(s.name);
    if ((param.is_nv() ? param.twin : param.name) == "MAXCURRENT")
      r.max_current_a = static_cast<double>(s.raw) * param.scale;
  }
  if (r.max_current_a > 0 || !p.motor.peak_current_a) return;
  const params::Param& max = db.get("NVMAXCURRENT");
  const double card_limit = static_cast<double>(max.max) * max.scale;
  r.max_current_a = std::min(*p.motor.peak_current_a, card_limit);
  basis.max_current_from =
      *p.motor.peak_current_a > card_limit
          ? format("the card's %.2f A limit (the motor's peak current is higher)", card_limit)
          : std::string("the motor's peak current");
}

void check_complete(const profile::TuneRequest& r) {
  std::string missing;
  const auto need = [&](double value, const std::string& what) {
    if (!(value > 0)) missing += (missing.empty() ? "" : ", ") + what;
  };
  need(r.motor.resistance_ohm, "--resistance (phase, e.g. 1.9ohm; --line-to-line for a data sheet's value)");
  need(r.motor.inductance_h, "--inductance (phase, e.g. 6.2mH; --line-to-line for a data sheet's value)");
  need(r.max_current_a, "--max-current (e.g. 8A)");
  need(r.bus_voltage_v, "--bus (DC bus voltage, e.g. 340V)");
  if (!missing.empty())
    throw UsageError("the tuning needs " + missing + "; give them as flags or through --from MOTOR-PROFILE");
}

profile::TuneRequest make_request(const TuneCliOptions& o, const params::ParamDb& db,
                                  const profile::Profile* motor, Basis& basis) {
  profile::TuneRequest r;
  if (motor) fill_from_profile(*motor, db, r, basis);
  if (o.line_to_line && o.resistance.empty() && o.inductance.empty())
    throw UsageError("--line-to-line says how to read -R and -L, and neither was given");
  // The equivalent star's phase value is half of what a meter reads between two leads.
  const double per_phase = o.line_to_line ? 0.5 : 1.0;
  if (!o.resistance.empty()) {
    r.motor.resistance_ohm = per_phase * quantity(Quantity::Resistance, "--resistance", o.resistance);
    basis.resistance_line_to_line = o.line_to_line;
  }
  if (!o.inductance.empty()) {
    r.motor.inductance_h = per_phase * quantity(Quantity::Inductance, "--inductance", o.inductance);
    basis.inductance_line_to_line = o.line_to_line;
  }
  if (!o.max_current.empty()) {
    r.max_current_a = quantity(Quantity::Current, "--max-current", o.max_current);
    basis.max_current_from.clear();
  }
  if (!o.bus.empty()) r.bus_voltage_v = quantity(Quantity::Voltage, "--bus", o.bus);
  if (!o.bandwidth.empty()) r.bandwidth_hz = bandwidth_hz(o.bandwidth);
  check_complete(r);
  return r;
}

struct Tuned {
  profile::TuneRequest request;
  Basis basis;
  profile::TuneResult result;
  profile::StepResponse step;
  profile::LoopVerdict verdict;
};

Tuned compute(const profile::TuneRequest& request, const Basis& basis, const params::ParamDb& db) {
  try {
    Tuned t{request, basis, profile::tune(request, db), {}, {}};
    profile::StepRequest step;
    step.motor = request.motor;
    step.max_current_a = request.max_current_a;
    step.bus_voltage_v = request.bus_voltage_v;
    step.kp = t.result.kp;
    step.ki = t.result.ki;
    step.reference = request.reference;
    step.sample_rate_hz = request.sample_rate_hz;
    t.step = profile::simulate_step(step);
    t.verdict = profile::judge_step(t.step);
    return t;
  } catch (const profile::TuneError& e) {
    throw UsageError(e.what());  // inputs that make no physical sense: nothing to compute
  }
}

// --overwrite was checked before (check_output_file): replacing here is what was asked.
void write_text_file(const std::string& path, const std::string& text) {
  write_file_atomically(path, text, /*overwrite=*/true);
}

// The tuning profile, written and then loaded back and validated like any other profile.
std::vector<profile::Finding> write_profile(const Tuned& t, const TuneCliOptions& o,
                                            const params::ParamDb& db, const profile::Profile* motor) {
  profile::TuningProfileOptions options;
  options.name = !o.name.empty() ? o.name : motor ? "tune-" + motor->name : "tuning";
  if (motor) {
    options.motor = motor->motor;
    options.supply_description = motor->supply.description;
  }
  // The motor data the gains were computed from, as given: line-to-line values where the
  // tuning read them so (twice the phase values written beside them), none where it did not.
  options.motor.line_to_line_resistance_ohm.reset();
  options.motor.line_to_line_inductance_h.reset();
  if (t.basis.resistance_line_to_line)
    options.motor.line_to_line_resistance_ohm = 2 * t.request.motor.resistance_ohm;
  if (t.basis.inductance_line_to_line)
    options.motor.line_to_line_inductance_h = 2 * t.request.motor.inductance_h;
  const auto tuned = profile::tuning_profile(t.request, t.result, t.step, db, options);
  write_text_file(o.out, profile::to_yaml(tuned, db));
  // Forced gains are validated as forced: loop-unstable is then the warning apply would give.
  return profile::validate(profile::load_profile_file(o.out, db), db, {nullptr, o.force, std::nullopt});
}

app::Json gains_json(const profile::PhysicalGains& g) {
  return app::Json::object().set("kp_v_per_a", g.kp_v_per_a).set("ki_v_per_as", g.ki_v_per_as);
}

app::Json optional_json(const std::optional<double>& v) {
  return v ? app::Json(*v) : app::Json();
}

app::Json tune_json(const Tuned& t, const TuneCliOptions& o, const std::vector<profile::Finding>& findings) {
  const auto& r = t.request;
  auto inputs = app::Json::object();
  inputs.set("resistance_ohm", r.motor.resistance_ohm).set("inductance_h", r.motor.inductance_h);
  inputs.set("max_current_a", r.max_current_a).set("bus_voltage_v", r.bus_voltage_v);
  inputs.set("bandwidth_hz", r.bandwidth_hz).set("sample_rate_hz", r.sample_rate_hz);
  const auto& m = t.step.metrics;
  auto step = app::Json::object();
  step.set("step_a", t.step.step_a).set("rise_time_s", optional_json(m.rise_time_s));
  step.set("overshoot_pct", m.overshoot_pct).set("settling_time_s", optional_json(m.settling_time_s));
  step.set("final_a", m.final_a)
      .set("saturated", m.saturated)
      .set("summary", profile::metrics_summary(t.step));
  auto j = app::Json::object();
  j.set("inputs", inputs).set("kqp", t.result.kp).set("kdp", t.result.kp).set("kqi", t.result.ki);
  j.set("kdi", t.result.ki).set("kp_exact", t.result.kp_exact).set("ki_exact", t.result.ki_exact);
  j.set("target", gains_json(t.result.target)).set("achieved", gains_json(t.result.achieved));
  j.set("warnings", render::findings_json(t.result.warnings)).set("step", step);
  j.set("svg", o.svg.empty() ? app::Json() : app::Json(o.svg));
  j.set("out", o.out.empty() ? app::Json() : app::Json(o.out));
  j.set("profile_findings", render::findings_json(findings));
  j.set("stable", t.verdict.acceptable)
      .set("verdict", t.verdict.acceptable ? app::Json() : app::Json(t.verdict.reason));
  j.set("line_to_line_input", t.basis.resistance_line_to_line || t.basis.inductance_line_to_line);
  j.set("max_current_from",
        t.basis.max_current_from.empty() ? app::Json() : app::Json(t.basis.max_current_from));
  return j;
}

std::string phase_basis(const Basis& b) {
  if (b.resistance_line_to_line && b.inductance_line_to_line) return ", half the line-to-line values given";
  if (b.resistance_line_to_line) return " (R: half the line-to-line value given)";
  if (b.inductance_line_to_line) return " (L: half the line-to-line value given)";
  return ", line to neutral as given";
}

void print_tune(const Tuned& t, const TuneCliOptions& o) {
  const auto& r = t.request;
  const auto& g = t.result;
  std::cout << "Current-loop gains (scaled from the manual's defaults; see profiles/TUNING.md)\n"
            << "  motor   R " << profile::format_quantity(Quantity::Resistance, r.motor.resistance_ohm)
            << ", L " << profile::format_quantity(Quantity::Inductance, r.motor.inductance_h) << " per phase"
            << phase_basis(t.basis) << " (L/R "
            << format("%.2f ms)", r.motor.inductance_h / r.motor.resistance_ohm * 1e3) << "\n"
            << "  drive   MAXCURRENT " << format("%.2f A", r.max_current_a)
            << (t.basis.max_current_from.empty() ? "" : " (" + t.basis.max_current_from + ")") << ", bus "
            << profile::format_quantity(Quantity::Voltage, r.bus_voltage_v) << ", bandwidth "
            << format("%.0f Hz", r.bandwidth_hz) << "\n"
            << "  KQP = KDP = " << g.kp << format("  (exact %.2f;", g.kp_exact)
            << format(" %.2f V/A)", g.achieved.kp_v_per_a) << "\n"
            << "  KQI = KDI = " << g.ki << format("  (exact %.1f;", g.ki_exact)
            << format(" %.0f V/(A s))", g.achieved.ki_v_per_as) << "\n";
  render::print_findings(std::cout, g.warnings, "tune");
  profile::TextPlotOptions plot;
  plot.unicode = !o.ascii;
  std::cout << "\nSimulated current step (locked rotor, " << format("%.0f kHz loop", r.sample_rate_hz / 1e3)
            << "):\n"
            << profile::step_response_text(t.step, plot);
}

// The model calls these gains unstable: show why, write nothing, exit 3 (refused).
void refuse_unstable(Context& ctx, const Tuned& t, const TuneCliOptions& o) {
  if (ctx.options.json)
    ctx.print_json(tune_json(t, TuneCliOptions{}, {}).set("refused", true));
  else
    print_tune(t, o);
  const double damped_hz = profile::kMaxDampedWcT * t.request.sample_rate_hz / (2.0 * std::numbers::pi);
  std::string written;
  if (!o.out.empty()) written += " " + o.out;
  if (!o.svg.empty()) written += " " + o.svg;
  throw Error(
      "these gains are unstable by the tuning model: " + t.verdict.reason + "; lower --bandwidth (the model" +
          format(" stays damped up to about %.0f Hz at this loop rate)", damped_hz) +
          (written.empty() ? "" : "; nothing written to" + written) + ", or pass --force to use them anyway",
      ErrorKind::Refused);
}

void run_tune(Context& ctx, const TuneCliOptions& o) {
  // As report -o and profile save: an existing file is replaced only when asked.
  check_output_file(o.out, o.overwrite);
  check_output_file(o.svg, o.overwrite);
  const auto& db = ctx.session().db();
  std::optional<profile::Profile> motor;
  try {
    if (!o.from.empty()) motor = profile::load_profile_file(o.from, db);
  } catch (const profile::ProfileError& e) {
    render::print_load_error(std::cerr, e, o.from);
    ctx.record(ops::Outcome::BadInput);
    return;
  }
  Basis basis;
  const auto request = make_request(o, db, motor ? &*motor : nullptr, basis);
  const Tuned t = compute(request, basis, db);
  if (!t.verdict.acceptable && !o.force) return refuse_unstable(ctx, t, o);
  if (!o.svg.empty()) write_text_file(o.svg, profile::step_response_svg(t.step));
  std::vector<profile::Finding> findings;
  if (!o.out.empty()) findings = write_profile(t, o, db, motor ? &*motor : nullptr);
  if (profile::has_errors(findings)) ctx.record(ops::Outcome::BadInput);
  if (ctx.options.json) return ctx.print_json(tune_json(t, o, findings));
  print_tune(t, o);
  if (!o.svg.empty()) std::cout << "Step response drawn in " << o.svg << "\n";
  if (!t.verdict.acceptable)
    std::cerr << "i20: warning: forced: " << t.verdict.reason
              << "; these gains are unstable by the tuning model\n";
  if (o.out.empty()) return;
  render::print_findings(std::cout, findings, o.out);
  std::cout << "Tuning profile written to " << o.out
            << (profile::has_errors(findings) ? " (INVALID, see above)" : "")
            << ": check it with `i20 profile validate " << o.out
            << "`, try it live first with `i20 profile apply " << o.out
            << " --to working`, then apply it to the EEPROM.\n";
}

}  // namespace

void register_tune_command(CLI::App& app, Context& ctx) {
  auto o = std::make_shared<TuneCliOptions>();
  auto* cmd = app.add_subcommand(
      "tune",
      "Current-loop gains KQP/KDP/KQI/KDI from the motor's phase R and L, MAXCURRENT, bus voltage and a "
      "bandwidth, scaled from the manual's defaults (a starting point: see profiles/TUNING.md). Shows the "
      "simulated step; --out writes a tuning profile. Needs no card");
  cmd->add_option("--from", o->from, "Motor profile giving R, L, bus voltage and MAXCURRENT (flags override)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--resistance,-R", o->resistance,
                  "Phase resistance, line to neutral, e.g. 1.9ohm (with --line-to-line: between two leads)");
  cmd->add_option("--inductance,-L", o->inductance,
                  "Phase inductance, line to neutral, e.g. 6.2mH (with --line-to-line: between two leads)");
  cmd->add_flag(
      "--line-to-line", o->line_to_line,
      "-R and -L are line-to-line values, as motor data sheets give them; the tuning uses half of each");
  cmd->add_option(
      "--max-current", o->max_current,
      "MAXCURRENT the gains are for, e.g. 8A (default with --from: the profile's MAXCURRENT, else the "
      "motor's peak current)");
  cmd->add_option("--bus", o->bus, "Nominal DC bus voltage, e.g. 340V");
  cmd->add_option("--bandwidth", o->bandwidth, "Current-loop bandwidth (default 500 Hz), e.g. 400Hz");
  cmd->add_option("--svg", o->svg, "Write the simulated step response as an SVG image");
  cmd->add_option("--out,-o", o->out, "Write the result as a tuning profile (YAML) to validate and apply");
  cmd->add_option("--name", o->name, "Name of the tuning profile (default: tune-<motor profile> or tuning)");
  cmd->add_flag("--ascii", o->ascii, "Plot with ASCII characters only");
  cmd->add_flag("--overwrite", o->overwrite, "Replace the --out and --svg files if they exist");
  cmd->add_flag("--force", o->force,
                "Write the profile even when the model's step overshoots more than 20% or does not settle "
                "(otherwise refused: exit 3, nothing written)");
  cmd->callback([&ctx, o] { run_tune(ctx, *o); });
}

}  // namespace i20::cli
