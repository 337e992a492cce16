// SPDX-License-Identifier: GPL-2.0-or-later
// wpd: write one 8I20 parameter by name, a drop-in for Mesa's WPD.
//   wpd NVMAXCURRENT 2500   -> EEPROM full-scale current 25 A (after a reset)
//   wpd BRAKEONV 30000      -> working brake-on voltage 300 V, live
//   wpd FAULT 0             -> clears faults (through CLEARFAULT, as the card requires)
//
// A one-cell write transaction (lib/ops): validated against the card's other values and the
// manual's rules, skipped when the card already holds it, verified, rolled back on failure.
#include <CLI/CLI.hpp>
#include <iostream>

#include "change_render.hpp"
#include "errors.hpp"
#include "ops/change.hpp"
#include "ops/core/errors.hpp"
#include "ops/core/signals.hpp"
#include "ops/core/timing.hpp"
#include "ops/faults.hpp"
#include "options.hpp"
#include "params/value.hpp"
#include "terminal.hpp"
#include "version/build_info.hpp"

using namespace i20;

namespace {

int clear_faults(ops::Session& session, const ops::WriteOptions& write) {
  const ops::FaultClear clear(session.db(), write);  // judged before the link opens
  const auto result = clear.run_on(session.amp());
  std::cout << "FAULT cleared through CLEARFAULT: was " << lbp::hex_value(result.fault_before, 4) << ", now "
            << lbp::hex_value(result.after.fault, 4) << "\n";
  if (result.faults_remain())
    std::cerr << "wpd: faults remain because their cause is still present; run `i20 "
              << session.endpoint().flags() << " faults` for details\n";
  return ops::exit_code(result.outcome());
}

// One line on success, like WPD; the full report when anything else happened.
int report(const ops::TargetRun& run, const params::ParamDb& db) {
  const auto& r = *run.result;
  if (run.outcome == ops::Outcome::Done || run.outcome == ops::Outcome::NothingToDo) {
    const auto& row = r.plan.steps.empty() ? r.plan.unchanged.front() : r.plan.steps.front();
    const auto& p = db.get(row.cell);
    std::cout << p.name << " = " << row.profile_raw;
    if (!p.unit.empty()) std::cout << " (" << row.profile_text << ")";
    std::cout << (r.plan.steps.empty() ? " already; nothing written" : " written and verified");
    if (p.is_nv() && (!r.plan.steps.empty() || !run.not_live.empty()))
      std::cout << " in EEPROM; takes effect after the 8I20 is reset (i20 " << run.target.flags()
                << " reset)";
    std::cout << "\n";
    for (const auto& event : r.events) std::cout << "note: " << event << "\n";
    return run.exit_code();
  }
  std::ostream& out = run.outcome == ops::Outcome::Refused || run.outcome == ops::Outcome::BadInput ||
                              run.outcome == ops::Outcome::Failed
                          ? std::cerr
                          : std::cout;
  if (&out == &std::cerr) {
    out << "wpd: " << (run.outcome == ops::Outcome::Failed ? "error" : "refused") << ": "
        << app::render::reason_text(r) << "\n";
    return run.exit_code();
  }
  app::render::print_run(out, run, db, "command line");
  std::cerr << "wpd: " << app::render::error_line(run) << "\n";
  return run.exit_code();
}

// The card settled after the command; a note when a mode had to be left, and exit 4 when the
// card did not confirm (which the command's own report already said).
int settled(ops::Session& session, int code) {
  const auto s = session.settle();
  if (s.note) app::print_line("wpd", *s.note);
  return s.outcome == ops::Outcome::Done || code != ops::exit_code(ops::Outcome::Done)
             ? code
             : ops::exit_code(s.outcome);
}

}  // namespace

static int run(int argc, char** argv) {
  CLI::App cli{
      "wpd: write an 8I20 parameter by its symbolic name (drop-in for Mesa's WPD).\n"
      "VALUE is a raw integer in the parameter's units (10 mV, 10 mA, ...), decimal or 0x hex.\n"
      "NV (EEPROM) parameters take effect after the 8I20 is reset. Every value is checked\n"
      "against its range and the manual's rules (BRAKEOFFV below BRAKEONV, ...) using the\n"
      "card's other values before anything is written, then verified by read-back.\n"
      "The port comes from COMPORT (and BAUDRATE, PROTOCOL=LBP) like WPD, or --port.\n"
      "Exit status: 0 written and verified, 1 card not reached, 2 bad input, 3 refused,\n"
      "4 card state uncertain or rolled back, 5 faults remain (WPD FAULT 0), 6 output not written, 130 "
      "Ctrl-C.\n"
      "Examples:\n  wpd NVMAXCURRENT 2500     (25 A)\n  wpd NVBRAKEONV 19000      (190 V)\n"
      "  wpd --sim BRAKEONV 30000  (300 V, live)"};
  cli.set_version_flag("--version", "wpd " + std::string(build::kVersion), "Print the version and exit");
  app::GlobalOptions options;
  ops::WriteOptions write;
  std::string name, value_text;
  cli.add_option("NAME", name, "Parameter name, e.g. NVMAXCURRENT")->required();
  cli.add_option("VALUE", value_text, "Raw integer value")->required();
  cli.add_flag("--allow-unverified", write.allow_unverified,
               "Write a working (RAM) address the database does not confirm for this firmware");
  cli.add_flag(
      "--force", write.force,
      "Write a guarded parameter (NVBAUDRATE, setpoints), or a threshold at or below the measured bus "
      "voltage; read why first");
  app::add_target_options(cli, options);
  app::add_database_options(cli, options);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app::report_parse_error(cli, e, "wpd");
  }
  app::set_overrides(app::overrides_of(cli));  // what its reports may name
  ops::install_stop_signals();  // SIGINT, SIGTERM, SIGHUP stop safely (ops::Session); SIGPIPE ignored
  options.legacy = ops::LegacyEnvironment::Required;
  try {
    ops::Session session(options, app::stop_acknowledgement("wpd"));
    try {
      const auto& db = session.db();
      const auto& param = db.get(name);
      const auto raw = params::parse_raw(param, value_text);
      // The manual's "WPD FAULT 0 would clear the FAULT parameter": FAULT itself is not
      // writable, the card clears faults through CLEARFAULT.
      if (param.name == "FAULT" && raw == 0) {
        const int code = clear_faults(session, write);
        return settled(session, code);
      }
      // Checked against every rule that needs no card before the link is even opened.
      const ops::ValueChange change({.values = {{name, value_text}},
                                     .syntax = ops::ValueSyntax::Raw,
                                     .force = write.force,
                                     .allow_unverified = write.allow_unverified,
                                     .cancel = session.cancel()},
                                    db);
      auto& amp = session.amp();
      return report(change.run_on(amp), amp.db());  // the run settles the card itself
    } catch (...) {
      return app::print_failure("wpd", session.fail());  // the card settled too: a mode may be on
    }
  } catch (...) {
    return app::report_current_exception("wpd");
  }
}

int main(int argc, char** argv) {
  // After the card is settled: a lost stdout changes nothing on it, but is not a success.
  return app::finish_output("wpd", run(argc, argv));
}
