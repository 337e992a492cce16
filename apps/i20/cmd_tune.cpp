// SPDX-License-Identifier: GPL-2.0-or-later
// i20 tune: KQP/KDP/KQI/KDI for a motor, what they mean (a simulated current step as an SVG
// and a terminal plot), and a tuning profile ready to validate and apply. Needs no card.
#include "cmd_tune.hpp"

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "context.hpp"
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
#include "change_render.hpp"

namespace i20::cli {
namespace {

namespace render = app::render;

using profile::Quantity;

struct TuneCliOptions {
  std::string from;  // a motor profile whose metadata gives what the flags do not
  std::string resistance, inductance, max_current, bus, bandwidth;
  std::string svg, out, name;
  bool ascii = false;
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

// The motor profile's metadata and MAXCURRENT, where it has them.
void fill_from_profile(const profile::Profile& p, const params::ParamDb& db, profile::TuneRequest& r) {
  r.motor.resistance_ohm = p.motor.phase_resistance_ohm.value_or(0);
  r.motor.inductance_h = p.motor.phase_inductance_h.value_or(0);
  r.bus_voltage_v = p.supply.bus_voltage_v.value_or(0);
  for (const auto& s : p.settings) {
    const params::Param& param = db.get(s.name);
    if ((param.is_nv() ? param.twin : param.name) == "MAXCURRENT")
      r.max_current_a = static_cast<double>(s.raw) * param.scale;
  }
}

void check_complete(const profile::TuneRequest& r) {
  std::string missing;
  const auto need = [&](double value, const std::string& what) {
    if (!(value > 0)) missing += (missing.empty() ? "" : ", ") + what;
  };
  need(r.motor.resistance_ohm, "--resistance (phase, line to neutral, e.g. 1.9ohm)");
  need(r.motor.inductance_h, "--inductance (phase, line to neutral, e.g. 6.2mH)");
  need(r.max_current_a, "--max-current (e.g. 8A)");
  need(r.bus_voltage_v, "--bus (DC bus voltage, e.g. 340V)");
  if (!missing.empty())
    throw UsageError("the tuning needs " + missing + "; give them as flags or through --from MOTOR-PROFILE");
}

profile::TuneRequest make_request(const TuneCliOptions& o, const params::ParamDb& db,
                                  const profile::Profile* motor) {
  profile::TuneRequest r;
  if (motor) fill_from_profile(*motor, db, r);
  if (!o.resistance.empty())
    r.motor.resistance_ohm = quantity(Quantity::Resistance, "--resistance", o.resistance);
  if (!o.inductance.empty())
    r.motor.inductance_h = quantity(Quantity::Inductance, "--inductance", o.inductance);
  if (!o.max_current.empty()) r.max_current_a = quantity(Quantity::Current, "--max-current", o.max_current);
  if (!o.bus.empty()) r.bus_voltage_v = quantity(Quantity::Voltage, "--bus", o.bus);
  if (!o.bandwidth.empty()) r.bandwidth_hz = bandwidth_hz(o.bandwidth);
  check_complete(r);
  return r;
}

struct Tuned {
  profile::TuneRequest request;
  profile::TuneResult result;
  profile::StepResponse step;
};

Tuned compute(const profile::TuneRequest& request, const params::ParamDb& db) {
  try {
    Tuned t{request, profile::tune(request, db), {}};
    profile::StepRequest step;
    step.motor = request.motor;
    step.max_current_a = request.max_current_a;
    step.bus_voltage_v = request.bus_voltage_v;
    step.kp = t.result.kp;
    step.ki = t.result.ki;
    step.reference = request.reference;
    step.sample_rate_hz = request.sample_rate_hz;
    t.step = profile::simulate_step(step);
    return t;
  } catch (const profile::TuneError& e) {
    throw UsageError(e.what());  // inputs that make no physical sense: nothing to compute
  }
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw Error("cannot write " + path);
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
  const auto tuned = profile::tuning_profile(t.request, t.result, t.step, db, options);
  write_text_file(o.out, profile::to_yaml(tuned, db));
  return profile::validate(profile::load_profile_file(o.out, db), db);
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
  return j;
}

void print_tune(const Tuned& t, const TuneCliOptions& o) {
  const auto& r = t.request;
  const auto& g = t.result;
  std::cout << "Current-loop gains (scaled from the manual's defaults; see profiles/TUNING.md)\n"
            << "  motor   R " << profile::format_quantity(Quantity::Resistance, r.motor.resistance_ohm)
            << ", L " << profile::format_quantity(Quantity::Inductance, r.motor.inductance_h)
            << " per phase (L/R " << format("%.2f ms)", r.motor.inductance_h / r.motor.resistance_ohm * 1e3)
            << "\n"
            << "  drive   MAXCURRENT " << format("%.2f A", r.max_current_a) << ", bus "
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

void run_tune(Context& ctx, const TuneCliOptions& o) {
  const auto db = app::load_database(ctx.options);
  std::optional<profile::Profile> motor;
  try {
    if (!o.from.empty()) motor = profile::load_profile_file(o.from, db);
  } catch (const profile::ProfileError& e) {
    render::print_load_error(std::cerr, e, o.from);
    ctx.exit_code = app::kBadInput;
    return;
  }
  const Tuned t = compute(make_request(o, db, motor ? &*motor : nullptr), db);
  if (!o.svg.empty()) write_text_file(o.svg, profile::step_response_svg(t.step));
  std::vector<profile::Finding> findings;
  if (!o.out.empty()) findings = write_profile(t, o, db, motor ? &*motor : nullptr);
  if (profile::has_errors(findings)) ctx.exit_code = app::kBadInput;
  if (ctx.options.json) return ctx.print_json(tune_json(t, o, findings));
  print_tune(t, o);
  if (!o.svg.empty()) std::cout << "Step response drawn in " << o.svg << "\n";
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
  cmd->add_option("--resistance,-R", o->resistance, "Phase resistance, line to neutral, e.g. 1.9ohm");
  cmd->add_option("--inductance,-L", o->inductance, "Phase inductance, line to neutral, e.g. 6.2mH");
  cmd->add_option("--max-current", o->max_current, "MAXCURRENT the gains are for, e.g. 8A");
  cmd->add_option("--bus", o->bus, "Nominal DC bus voltage, e.g. 340V");
  cmd->add_option("--bandwidth", o->bandwidth, "Current-loop bandwidth (default 500 Hz), e.g. 400Hz");
  cmd->add_option("--svg", o->svg, "Write the simulated step response as an SVG image");
  cmd->add_option("--out,-o", o->out, "Write the result as a tuning profile (YAML) to validate and apply");
  cmd->add_option("--name", o->name, "Name of the tuning profile (default: tune-<motor profile> or tuning)");
  cmd->add_flag("--ascii", o->ascii, "Plot with ASCII characters only");
  cmd->callback([&ctx, o] { run_tune(ctx, *o); });
}

}  // namespace i20::cli
