// SPDX-License-Identifier: GPL-2.0-or-later
// i20 commission: find an 8I20 axis's commutation over Ethernet, check it in closed loop and
// write bldc's setup. Parses options, prints the plan and asks, renders the report: every
// decision is lib/ops/commission's.
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <type_traits>
#include <variant>

#include "commission/format.hpp"
#include "context.hpp"
#include "ops/commission/commission.hpp"
#include "output_file.hpp"

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

void print_text(const ops::CommissionReport& r) {
  std::cout << "commission " << r.plan.preflight.target.url() << ": " << r.message << "\n";
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
  auto& session = ctx.session();
  const auto plan = ops::prepare_commission(session, a.o);
  std::cerr << "i20 commission: the plan\n";
  for (const auto& line : plan.lines()) std::cerr << "  " << line << "\n";
  if (!a.yes)
    ctx.require_confirmation(
        "Drive the motor on " + plan.preflight.target.url() + " as planned? Keep clear of the axis",
        "commission not confirmed; the motor was not driven (pass --yes in scripts)");
  const auto report = ops::run_commission(
      session, plan, a.o, [](const std::string& phase) { std::cerr << "i20 commission: " << phase << "\n"; });
  const auto tree = report_json(report);
  if (ctx.options.json)
    ctx.print_json(tree);
  else if (a.yaml)
    std::cout << report_yaml(tree);
  else
    print_text(report);
  ctx.record(report.outcome());
  if (!report.current_zeroed) std::cerr << "i20: card state: " << report.zero_note << "\n";
  if (a.out.empty()) return;
  if (report.outcome() != ops::Outcome::Done) {
    std::cerr << "i20: " << a.out << " not written: the commissioning did not complete\n";
    return;
  }
  write_file_atomically(a.out, ops::commission_hal_fragment(report), a.overwrite);
  std::cerr << "i20: wrote " << a.out << "\n";
}

}  // namespace

void register_commission_command(CLI::App& app, Context& ctx) {
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
