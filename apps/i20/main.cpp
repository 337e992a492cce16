// SPDX-License-Identifier: GPL-2.0-or-later
// i20: the umbrella CLI for Mesa 8I20 servo amplifiers.
#include <CLI/CLI.hpp>
#include <iostream>

#include "cmd_doctor.hpp"
#include "cmd_inventory.hpp"
#include "cmd_pid.hpp"
#include "context.hpp"
#include "ops/core/signals.hpp"
#include "params/closest.hpp"
#include "terminal.hpp"
#include "version/build_info.hpp"

using namespace i20;

namespace {

// "unknown command 'inof': did you mean info?" when the first unexpected word looks like a
// mistyped subcommand; empty otherwise (CLI11's own message then).
// CLI11 says "The following arguments were not expected: inof" when another word came
// first, and "A subcommand is required" when the mistyped word was the only one.
std::string unknown_command(const CLI::App& app, const CLI::ParseError& e) {
  std::string word;
  if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr && app.get_subcommands().empty()) {
    const std::string what = e.what();
    const auto colon = what.find(": ");
    if (colon == std::string::npos) return {};
    word = what.substr(colon + 2);
  } else if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr && app.get_subcommands().empty() &&
             !app.remaining().empty()) {
    word = app.remaining().front();
  } else {
    return {};
  }
  word = word.substr(0, word.find_first_of(" ,"));
  if (word.empty() || word.front() == '-' || word.find_first_of("/.:=") != std::string::npos) return {};
  std::vector<i20::params::Candidate> names;
  for (const auto* sub : app.get_subcommands({})) names.push_back({sub->get_name(), {sub->get_name()}});
  const auto near = i20::params::closest(word, names, 1);
  return "unknown command '" + word + "'" +
         (near.empty() ? "; `i20 --help` lists them" : ": did you mean " + near.front() + "?");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "i20: set up Mesa 8I20 servo amplifiers: read and write parameters by name, decode and clear\n"
      "faults, apply motor profiles. Talks to the card over a serial RS-422 adapter (3I21/3I22, jumper\n"
      "W6 down = setup mode, 115200 baud), over Ethernet through a 7I96S/7I92T, or to the built-in\n"
      "simulator (--sim), which is the way to try everything without hardware.\n\n"
      "Try:  i20 --sim info   |   i20 --sim dump   |   i20 --sim set NVBRAKEONV=370V"};
  app.set_version_flag("--version", "i20 " + std::string(build::kVersion), "Print the version and exit");
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand
  cli::Context ctx;
  app::add_target_options(app, ctx.options);
  app::add_database_options(app, ctx.options);
  app.add_flag("--json", ctx.options.json, "Machine-readable JSON output");
  cli::register_param_commands(app, ctx);
  cli::register_discover_command(app, ctx);
  cli::register_fault_commands(app, ctx);
  cli::register_profile_commands(app, ctx);
  cli::register_scan_command(app, ctx);
  cli::register_report_command(app, ctx);
  cli::register_inventory_command(app, ctx);
  cli::register_hal_commands(app, ctx);
  cli::register_commission_command(app, ctx);  // apps/i20/cmd_commission.cpp
  cli::register_console_command(app, ctx);
  cli::register_doctor_command(app, ctx);  // apps/i20/cmd_doctor.cpp
  cli::register_pid_command(app, ctx);     // apps/i20/cmd_pid.cpp
  // Before the command runs: what it reports may name the options that override a refusal,
  // and only those the command has (`i20 set` has --force, `i20 faults clear` has not).
  app.parse_complete_callback([&app] { app::set_overrides(app::overrides_of_parsed(app)); });

  ops::install_stop_signals();  // SIGINT, SIGTERM, SIGHUP stop safely (ops::Session); SIGPIPE ignored
  try {
    app.parse(argc, argv);
    ctx.settle();
  } catch (const CLI::ParseError& e) {
    // --json callers get JSON for errors before the command starts too.
    if (e.get_exit_code() != 0 && app::json_requested(argc, argv))
      app::print_failure_json({.outcome = ops::Outcome::BadInput, .lines = {{"error", e.what()}}});
    if (const auto hint = unknown_command(app, e); !hint.empty()) {
      std::cerr << "i20: error: " << hint << "\n";
      return ops::exit_code(ops::Outcome::BadInput);
    }
    return app::report_parse_error(app, e, "i20");
  } catch (...) {
    ctx.print_notes();
    const int code = ctx.report_failure();
    return app::finish_output("i20", code);  // said after the card is settled
  }
  ctx.print_notes();
  return app::finish_output("i20", ctx.exit_code());  // a report that did not land is not a success
}
