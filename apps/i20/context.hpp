// SPDX-License-Identifier: GPL-2.0-or-later
// State shared by the i20 subcommands: global options and a lazily opened session.
#pragma once

#include <iosfwd>
#include <memory>

#include "errors.hpp"
#include "json.hpp"
#include "session.hpp"

namespace CLI {
class App;
}

namespace i20::cli {

struct Context {
  app::GlobalOptions options;
  int exit_code = app::kOk;

  // Opened on first use, with COMPORT/BAUDRATE/PROTOCOL read like wpd and rpd do.
  app::Session& session();
  ops::Card& card() { return session().card(); }
  // The options that name the target, for advice lines ("--port /dev/ttyUSB0").
  std::string target_flags() { return session().endpoint().flags(); }
  // The card left as it must be (no NV/RPC memory mode on) before the program ends.
  void settle() {
    if (session_ && session_->settle("i20") != app::kOk && exit_code == app::kOk) exit_code = app::kCardState;
  }
  // The one-line report of the exception being handled, and the card settled (see
  // app::Session::report_failure). Call from a catch (...) block.
  int report_failure() {
    return session_ ? session_->report_failure("i20") : app::report_current_exception("i20");
  }
  // Prints JSON documents the same way everywhere.
  void print_json(const app::Json& json) const;
  // Asks "question [y/N]" on the terminal; false without a terminal (use --yes there).
  bool confirm(const std::string& question) const;
  // Verbose link notes and statistics to stderr.
  void print_notes();

 private:
  std::unique_ptr<app::Session> session_;
};

// Each registers its subcommands on the umbrella app.
void register_param_commands(CLI::App& app, Context& ctx);
void register_discover_command(CLI::App& app, Context& ctx);
void register_fault_commands(CLI::App& app, Context& ctx);    // faults, clear-faults, watch
void register_profile_commands(CLI::App& app, Context& ctx);  // profile, tune
void register_scan_command(CLI::App& app, Context& ctx);      // scan (Ethernet)
void register_report_command(CLI::App& app, Context& ctx);    // report (field service)

}  // namespace i20::cli
