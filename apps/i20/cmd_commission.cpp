// SPDX-License-Identifier: GPL-2.0-or-later
// i20 commission: find an 8I20 axis's commutation over Ethernet, check it in closed loop and
// write bldc's setup. Parses options, prints the plan and asks, renders the report: every
// decision is lib/ops/commission's.
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "commission/format.hpp"
#include "context.hpp"
#include "ops/commission.hpp"
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
void finding(YAML::Emitter& y, const char* key, const std::optional<commission::Finding<T>>& f) {
  if (!f) return;
  y << YAML::Key << key << YAML::Value << YAML::BeginMap << YAML::Key << "value" << YAML::Value << f->value
    << YAML::Key << "uncertainty" << YAML::Value << f->uncertainty << YAML::Key << "how" << YAML::Value
    << f->how << YAML::EndMap;
}

// The report as one YAML document; --json converts the same tree.
std::string report_yaml(const ops::CommissionReport& r) {
  YAML::Emitter y;
  y << YAML::BeginMap;
  y << YAML::Key << "target" << YAML::Value << r.plan.preflight.target.url();
  y << YAML::Key << "stop" << YAML::Value << std::string(ops::stop_reason_name(r.stop));
  y << YAML::Key << "message" << YAML::Value << r.message;
  y << YAML::Key << "current_zeroed" << YAML::Value << r.current_zeroed;
  if (!r.zero_note.empty()) y << YAML::Key << "zero_note" << YAML::Value << r.zero_note;
  if (r.encoder_instance) y << YAML::Key << "encoder" << YAML::Value << *r.encoder_instance;
  y << YAML::Key << "hall_inputs" << YAML::Value << YAML::Flow << r.hall_pins;
  if (r.bldc) {
    y << YAML::Key << "bldc" << YAML::Value << YAML::BeginMap;
    if (r.bldc->pattern) y << YAML::Key << "pattern" << YAML::Value << *r.bldc->pattern;
    if (r.bldc->poles) y << YAML::Key << "poles" << YAML::Value << *r.bldc->poles;
    if (r.bldc->scale) y << YAML::Key << "scale" << YAML::Value << *r.bldc->scale;
    if (r.bldc->encoder_offset) y << YAML::Key << "encoder-offset" << YAML::Value << *r.bldc->encoder_offset;
    y << YAML::Key << "missing" << YAML::Value << r.bldc->missing;
    y << YAML::EndMap;
  }
  if (r.result) {
    const auto& f = *r.result;
    y << YAML::Key << "findings" << YAML::Value << YAML::BeginMap;
    finding(y, "encoder_direction", f.encoder_direction);
    finding(y, "counts_per_electrical_turn", f.counts_per_electrical_turn);
    finding(y, "pole_pairs", f.pole_pairs);
    finding(y, "counts_per_turn", f.counts_per_turn);
    finding(y, "index_electrical_angle_deg", f.index_electrical_angle_deg);
    finding(y, "encoder_offset_counts", f.encoder_offset_counts);
    finding(y, "hall_pattern", f.hall.bldc_pattern);
    finding(y, "friction_lag_deg", f.friction_lag_deg);
    y << YAML::EndMap;
    y << YAML::Key << "problems" << YAML::Value << YAML::BeginSeq;
    for (const auto& p : f.problems) y << p.message;
    y << YAML::EndSeq;
  }
  if (r.check) {
    y << YAML::Key << "check" << YAML::Value << YAML::BeginMap << YAML::Key << "passed" << YAML::Value
      << r.check->passed;
    y << YAML::Key << "moved_electrical_turns" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const auto& d : r.check->directions) y << d.moved_electrical_turns;
    y << YAML::EndSeq << YAML::Key << "hold_errors_deg" << YAML::Value << YAML::Flow
      << r.check->hold_errors_deg;
    y << YAML::Key << "bound_deg" << YAML::Value << r.check->bound_deg;
    y << YAML::Key << "how" << YAML::Value << r.check->how << YAML::EndMap;
  }
  y << YAML::Key << "notes" << YAML::Value << r.notes;
  y << YAML::Key << "samples" << YAML::Value << r.samples;
  y << YAML::Key << "elapsed_s" << YAML::Value << r.elapsed_s;
  y << YAML::Key << "doit_period_us" << YAML::Value << YAML::BeginMap << YAML::Key << "p50" << YAML::Value
    << r.doit.percentile(50).count() << YAML::Key << "p99" << YAML::Value << r.doit.percentile(99).count()
    << YAML::Key << "worst" << YAML::Value << r.doit.worst().count() << YAML::Key << "late" << YAML::Value
    << r.doit.late << YAML::Key << "missed" << YAML::Value << r.doit.missed << YAML::EndMap;
  y << YAML::EndMap;
  return std::string(y.c_str()) + "\n";
}

app::Json scalar_json(const std::string& s, bool quoted) {
  if (quoted) return app::Json(s);
  if (s == "true") return app::Json(true);
  if (s == "false") return app::Json(false);
  long long i = 0;
  auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), i);
  if (ec == std::errc() && p == s.data() + s.size()) return app::Json(i);
  double d = 0;
  auto [q, ec2] = std::from_chars(s.data(), s.data() + s.size(), d);
  if (ec2 == std::errc() && q == s.data() + s.size() && std::isfinite(d)) return app::Json(d);
  return app::Json(s);
}

app::Json to_json(const YAML::Node& node) {
  if (node.IsMap()) {
    auto j = app::Json::object();
    for (const auto& kv : node) j.set(kv.first.as<std::string>(), to_json(kv.second));
    return j;
  }
  if (node.IsSequence()) {
    auto j = app::Json::array();
    for (const auto& item : node) j.push(to_json(item));
    return j;
  }
  if (node.IsScalar()) return scalar_json(node.Scalar(), node.Tag() == "!");
  return app::Json();
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
  const std::string yaml = report_yaml(report);
  if (ctx.options.json)
    ctx.print_json(to_json(YAML::Load(yaml)));
  else if (a.yaml)
    std::cout << yaml;
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
