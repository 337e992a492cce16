// SPDX-License-Identifier: GPL-2.0-or-later
// i20 hal: writes a LinuxCNC HAL file for 8I20 axes on a 7I96S/7I92T.
// i20 hal lint FILE...: checks LinuxCNC HAL files for the 8I20 mistakes old sample configs
// and PnCconf carry. Both are offline: no card is opened.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <fstream>
#include <iostream>
#include <sstream>

#include "context.hpp"
#include "linuxcnc/hal_design.hpp"
#include "linuxcnc/hal_generate.hpp"
#include "linuxcnc/hal_lint.hpp"
#include "linuxcnc/ini_check.hpp"
#include "ops/hal_file.hpp"
#include "ops/hal_lint_load.hpp"
#include "output_file.hpp"
#include "params/text.hpp"
#include "profile/loader.hpp"
#include "profile/quantity.hpp"
#include "profile_lookup.hpp"

namespace i20::cli {
namespace {

namespace L = i20::linuxcnc;

// "12", "12A", "12 A", "800mA": amps.
// A current with its unit ("12A", "500mA"), as every other command takes one: a bare number
// is refused rather than guessed to be amps.
double parse_amps(const std::string& option, const std::string& text) {
  if (L::number(text))
    throw UsageError(option + " " + text + ": give the unit, e.g. " + text + "A (amps) or " + text + "mA");
  std::string why;
  const auto v = profile::parse_quantity(profile::Quantity::Current, text, why);
  if (!v) throw UsageError(option + " " + text + ": " + why);
  return *v;
}

// The MAXCURRENT a motor profile sets (working or NV value), in amps.
double profile_max_current(Context& ctx, const std::string& file) {
  const auto& db = ctx.session().db();
  const auto p = profile::load_profile_file(file, db);
  for (const auto& s : p.settings) {
    const params::Param& param = db.get(s.name);
    if ((param.is_nv() ? param.twin : param.name) == "MAXCURRENT")
      return static_cast<double>(s.raw) * param.scale;
  }
  throw UsageError("profile " + file + " sets no MAXCURRENT or NVMAXCURRENT: give --max-current");
}

// --max-current, else the profile's MAXCURRENT, else none.
std::optional<double> max_current(Context& ctx, const std::string& text, const std::string& profile_file) {
  if (!text.empty()) return parse_amps("--max-current", text);
  if (!profile_file.empty()) return profile_max_current(ctx, profile_file);
  return std::nullopt;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw UsageError("cannot read " + path);
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) throw UsageError("cannot read " + path);
  return text.str();
}

// ------------------------------------------------------------------ lint
struct LintCliOptions {
  std::vector<std::string> files;
  std::string max_current;
  std::string profile;
  std::optional<int> pattern;
  bool load = false;
  std::string ini;
};

app::Json finding_json(const L::LintFinding& f) {
  auto j = app::Json::object();
  j.set("file", f.at.file).set("line", f.at.line);
  j.set("severity", f.severity == L::LintSeverity::Error ? "error" : "warning");
  j.set("rule", f.rule).set("message", f.message).set("fix", f.fix);
  return j.set("halcmd_refuses", f.refused_by_halcmd);
}

// --load: the files run in halrun against the virtual card; halcmd's complaints join the
// findings.
void add_load_findings(const std::vector<L::HalSource>& sources, const LintCliOptions& o,
                       std::vector<L::LintFinding>& findings) {
  const auto ini =
      o.ini.empty() ? std::optional<std::string>() : std::optional<std::string>(read_file(o.ini));
  const auto loaded = ops::load_in_halrun(sources, ini, own_executable());
  L::add_halrun_findings(findings, loaded.findings);
  std::cerr << "i20: loaded in halrun against " << loaded.ran << ": " << loaded.findings.size() << " name"
            << (loaded.findings.size() == 1 ? "" : "s") << " halcmd rejected";
  if (!loaded.left_out.empty())
    std::cerr << "; " << loaded.left_out.size() << " line" << (loaded.left_out.size() == 1 ? "" : "s")
              << " left out (they need a running LinuxCNC), first "
              << params::printable(loaded.left_out.front());
  std::cerr << "\n";
}

void run_lint(Context& ctx, const LintCliOptions& o) {
  L::LintOptions options;
  options.max_current = max_current(ctx, o.max_current, o.profile);
  options.pattern = o.pattern;
  std::vector<L::HalSource> sources;
  std::vector<L::Statement> statements;
  for (const auto& file : o.files) {
    std::string text = read_file(file);
    auto s = L::read_hal(text, file);  // HalSyntaxError: exit 2, FILE:LINE named
    statements.insert(statements.end(), s.begin(), s.end());
    sources.push_back({file, std::move(text), std::move(s)});
  }
  auto findings = L::lint(statements, options);
  if (!o.ini.empty()) {
    const auto more = L::check_ini(statements, read_file(o.ini), o.ini);
    findings.insert(findings.end(), more.begin(), more.end());
  }
  if (o.load) add_load_findings(sources, o, findings);
  // In file and line order, the HAL files as given, the INI after them.
  const auto order = [&](const L::LintFinding& f) {
    const auto it =
        std::find_if(sources.begin(), sources.end(), [&](const auto& s) { return s.file == f.at.file; });
    return std::pair{it - sources.begin(), f.at.line};
  };
  std::stable_sort(findings.begin(), findings.end(),
                   [&](const auto& a, const auto& b) { return order(a) < order(b); });
  if (ctx.options.json) {
    auto list = app::Json::array();
    for (const auto& f : findings) list.push(finding_json(f));
    ctx.print_json(app::Json::object().set("files", static_cast<int>(o.files.size())).set("findings", list));
  } else {
    // A finding quotes the file: never a raw control character on the terminal.
    for (const auto& f : findings) std::cout << params::printable(L::to_string(f)) << "\n";
  }
  const auto errors = std::count_if(findings.begin(), findings.end(),
                                    [](const auto& f) { return f.severity == L::LintSeverity::Error; });
  if (!findings.empty() && !ctx.options.json)
    std::cerr << "i20: " << errors << " error" << (errors == 1 ? "" : "s") << ", " << findings.size() - errors
              << " warning" << (findings.size() - errors == 1 ? "" : "s") << "\n";
  // Exit 1 for findings, as diff(1) reports a difference; 2 when halcmd would refuse a line
  // by its own rules, as for a line it cannot read.
  const int code = L::lint_exit_code(findings);
  if (code == 2) ctx.record(ops::Comparison::Trouble);
  if (code == 1) ctx.record(ops::Comparison::Differs);
}

// ------------------------------------------------------------------ generate
struct HalCliOptions {
  L::HalPlan plan;
  std::string max_current;
  std::string profile;
  std::string out;
  bool overwrite = false;
};

// The options that made the file, for its header.
std::string command_line(const L::HalPlan& p) {
  std::ostringstream c;
  c << "i20 hal --board " << p.board << " --board-ip " << p.board_ip << " --axes " << p.axes << " --cfg "
    << p.cfg;
  if (p.pattern) c << " --pattern " << *p.pattern;
  if (p.poles) c << " --poles " << *p.poles;
  if (p.counts_per_rev) c << " --counts-per-rev " << *p.counts_per_rev;
  if (p.encoder_offset) c << " --encoder-offset " << *p.encoder_offset;
  if (p.max_current) c << " --max-current " << *p.max_current << "A";
  for (const auto& h : p.halls) c << " --halls " << h;
  if (!p.estop_in.empty()) c << " --estop-in " << p.estop_in;
  if (p.notch) c << " --notch";
  return c.str();
}

void run_generate(Context& ctx, const HalCliOptions& o) {
  auto plan = o.plan;
  plan.max_current = max_current(ctx, o.max_current, o.profile);
  plan.command_line = command_line(plan);
  L::check_plan(plan);                    // bad options first: they are the user's to fix
  check_output_file(o.out, o.overwrite);  // before any work: a refusal costs nothing
  const std::string text = ops::generate_hal_file(plan);
  if (o.out.empty() || o.out == "-") {
    std::cout << text;
    return;
  }
  write_file_atomically(o.out, text, o.overwrite);
  std::cerr << "Wrote " << o.out << ": check it with `i20 hal lint " << o.out << "`\n";
}

}  // namespace

void register_hal_commands(CLI::App& app, Context& ctx) {
  auto o = std::make_shared<HalCliOptions>();
  auto* hal = app.add_subcommand(
      "hal",
      "Write a LinuxCNC HAL file for 8I20 axes on a 7I96S or 7I92T: bldc rotor-angle to the 8I20's angle, a "
      "position pid whose output is the current in amps (at most MAXCURRENT), every 8I20 fault pin in the "
      "E-stop chain, and a comment block with the INI values it reads. `i20 hal lint` checks HAL files. "
      "Needs no card");
  hal->require_subcommand(0, 1);
  auto& p = o->plan;
  hal->add_option("--board", p.board, "The Ethernet card: 7i96s (hm2_7i96s.0) or 7i92t (hm2_7i92.0)")
      ->capture_default_str();
  hal->add_option("--board-ip", p.board_ip, "The card's IP address (hm2_eth board_ip)")
      ->capture_default_str();
  hal->add_option("--axes", p.axes, "8I20 axes; axis k uses smart-serial port 0 channel k and encoder k")
      ->capture_default_str();
  hal->add_option(
         "--cfg", p.cfg,
         "bldc cfg: qh (Halls, then the encoder), qhi (Halls until the index, then the encoder) or h "
         "(Halls only)")
      ->capture_default_str();
  hal->add_option("--pattern", p.pattern, "bldc Hall pattern 0-47 (cfg with h; from commissioning)");
  hal->add_option("--poles", p.poles, "Motor poles, not pole pairs (cfg with q)");
  hal->add_option(
      "--counts-per-rev", p.counts_per_rev,
      "Encoder counts per motor revolution, bldc's scale (cfg with q; negative reverses commutation)");
  hal->add_option("--encoder-offset", p.encoder_offset, "Counts from the index to electrical zero (cfg qhi)");
  hal->add_option("--max-current", o->max_current,
                  "The card's MAXCURRENT with its unit, e.g. 12A: the pid's output limit (this or --profile "
                  "is required)");
  hal->add_option("--halls", p.halls,
                  "The HAL pins of Hall 1,2,3, comma-separated, once per axis (cfg with h), e.g. "
                  "hm2_7i96s.0.inm.00.input-00,hm2_7i96s.0.inm.00.input-01,hm2_7i96s.0.inm.00.input-02");
  hal->add_option("--estop-in", p.estop_in,
                  "The pin that is true while the E-stop loop is closed (default: left for you to net to "
                  "estop-ext; until then the machine stays in E-stop)");
  hal->add_flag(
      "--notch", p.notch,
      "A notch after each pid (LinuxCNC's biquad), as `i20 pid --notch` designs the loop of a two-mass "
      "axis: its coefficients come from [JOINT_k]NOTCH_N0, NOTCH_N1, NOTCH_N2, NOTCH_D1, NOTCH_D2");
  hal->add_option("--output,-o", o->out, "Write the HAL file here (default: standard output)");
  hal->add_flag("--overwrite", o->overwrite, "Replace the --output file if it exists");
  hal->add_option("--profile", o->profile,
                  "A motor profile (name or file) whose MAXCURRENT is the limit, instead of --max-current")
      ->transform(profile_file())
      ->excludes("--max-current");
  hal->callback([&ctx, hal, o] {
    if (hal->get_subcommands().empty()) run_generate(ctx, *o);
  });

  auto lo = std::make_shared<LintCliOptions>();
  auto* lint = hal->add_subcommand(
      "lint",
      "Check LinuxCNC HAL files for 8I20 mistakes: pins removed in 2012 (amp_enable, max_current, ...), "
      "phase-angle into the 8I20's angle, current scaling, bldc pins its cfg does not create, initvalue 0, "
      "fault pins that reach nothing, PnCconf's '..' names, misspelt 8I20, encoder, bldc and pid names "
      "(aliases resolved), and what halcmd refuses (a module loaded twice, a pin on two signals, a signal "
      "of two types or two writers, setp of a linked pin or an output). Give all files of one configuration "
      "(HALFILE and POSTGUI_HALFILE). Prints FILE:LINE: error|warning: ...; exit 0 clean, 1 findings, 2 "
      "unreadable or a line halcmd refuses by its own rules");
  lint->add_option("files", lo->files, "HAL files, in the order LinuxCNC runs them")->required();
  lint->add_option(
      "--max-current", lo->max_current,
      "The card's MAXCURRENT with its unit, e.g. 12A: report current commands that can exceed it");
  lint->add_option("--profile", lo->profile,
                   "A motor profile (name or file) whose MAXCURRENT is the limit, instead of --max-current")
      ->transform(profile_file())
      ->excludes("--max-current");
  lint->add_option("--pattern", lo->pattern,
                   "The Hall pattern commissioning found: report every bldc with Halls that uses another");
  lint->add_flag(
      "--load", lo->load,
      "Also run the files in LinuxCNC's halrun against a virtual 7I96S or 7I92T (i20sim, in network "
      "namespaces of its own: needs root and linuxcnc-uspace) and report every pin, parameter or "
      "function halcmd says does not exist on its line. Lines that need a running LinuxCNC "
      "(loadusr, iocontrol, halui, GUI pins) are left out and counted");
  lint->add_option(
      "--ini", lo->ini,
      "The configuration's INI file: every [SECTION]KEY the files read must be in it (halcmd stops at "
      "one that is not), a joint's notch from i20 pid --notch must be run by the files, and --load "
      "runs with it");
  lint->callback([&ctx, lo] { run_lint(ctx, *lo); });
}

}  // namespace i20::cli
