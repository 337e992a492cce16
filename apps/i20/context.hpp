// SPDX-License-Identifier: GPL-2.0-or-later
// State shared by the i20 subcommands: global options, a lazily opened ops::Session, and the
// outcome the command reached (the exit code is ops::exit_code of it, nowhere else).
#pragma once

#include <iosfwd>
#include <memory>
#include <optional>

#include "errors.hpp"
#include "json.hpp"
#include "options.hpp"

namespace CLI {
class App;
}

namespace i20::cli {

struct Context {
  app::GlobalOptions options;

  // Opened on first use, with COMPORT/BAUDRATE/PROTOCOL read like wpd and rpd do.
  ops::Session& session();
  ops::Amp& amp() { return session().amp(); }
  // The options that name the target, for advice lines ("--port /dev/ttyUSB0").
  std::string target_flags() { return session().endpoint().flags(); }

  // What the command reached; several (a fleet, a settle after a report) keep the most
  // serious (ops::most_serious).
  void record(ops::Outcome outcome) { outcome_ = ops::most_serious(outcome_, outcome); }
  // `i20 profile diff` answers as diff(1) does (ops::Comparison).
  void record(ops::Comparison comparison) { comparison_ = comparison; }
  int exit_code() const;

  // The card left as it must be (no NV/RPC memory mode on) before the program ends; a note
  // on stderr when a mode had to be left.
  void settle();
  // The lines of the exception being handled, and the card settled (ops::Session::fail),
  // printed; returns the exit code. Call from a catch block.
  int report_failure();
  // Prints JSON documents the same way everywhere.
  void print_json(const app::Json& json) const;
  // Asks "question [y/N]" on the terminal; false without a terminal (use --yes there).
  bool confirm(const std::string& question) const;
  // Asks `question`; unless the answer is yes, throws UsageError(refusal) (exit 2, rendered as
  // every error is: one line, or a JSON object with --json). `refusal` says what was not done.
  void require_confirmation(const std::string& question, const std::string& refusal) const;
  // Verbose link notes and statistics to stderr.
  void print_notes();

 private:
  ops::Outcome outcome_ = ops::Outcome::Done;
  std::optional<ops::Comparison> comparison_;
  std::unique_ptr<ops::Session> session_;
};

// Each registers its subcommands on the umbrella app.
void register_param_commands(CLI::App& app, Context& ctx);
void register_discover_command(CLI::App& app, Context& ctx);
void register_fault_commands(CLI::App& app, Context& ctx);      // faults, clear-faults, watch
void register_profile_commands(CLI::App& app, Context& ctx);    // profile, tune
void register_scan_command(CLI::App& app, Context& ctx);        // scan (Ethernet)
void register_report_command(CLI::App& app, Context& ctx);      // report (field service)
void register_hal_commands(CLI::App& app, Context& ctx);        // hal, hal lint (LinuxCNC HAL files)
void register_commission_command(CLI::App& app, Context& ctx);  // commission (Ethernet)
void register_console_command(CLI::App& app, Context& ctx);     // console (web console, lib/console)

}  // namespace i20::cli
