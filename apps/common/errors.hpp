// SPDX-License-Identifier: GPL-2.0-or-later
// How the apps print what went wrong: one line per report line, "PROGRAM: LABEL: MESSAGE", on
// stderr. What a failure means and its exit code are lib/ops's (ops::Session::fail,
// ops::failure_of_current_exception, ops::exit_code); no app decides either.
#pragma once

#include <string>

#include "ops/core/session.hpp"
#include "parse_error.hpp"

namespace i20::app {

// The options that override a refusal which this program (for i20: the command being run)
// has. lib/ names none of them (ops::Advice says which kind overrides a refusal); the app
// names the one it has, and says nothing for one it lacks.
struct Overrides {
  bool take_over = false;         // --take-over (add_target_options)
  bool force = false;             // --force
  bool allow_unverified = false;  // --allow-unverified
};
// Set once, after the arguments are parsed and before the command runs: every render site
// (errors, transaction reasons, profile findings) then names only these. None until set.
void set_overrides(const Overrides& overrides);
const Overrides& overrides();

// What the app adds after a message whose advice is `advice`, when the program has the
// option: " (--take-over)" beside a running host, "; pass --force to override",
// "; pass --allow-unverified if you know better"; empty for none or an option it lacks.
std::string advice_text(ops::Advice advice);
// A message from lib/ with the option that overrides it, if this program has one.
std::string with_advice(const std::string& message, ops::Advice advice);

// "PROGRAM: LABEL: MESSAGE[SUFFIX]" on stderr: every line the apps print from lib/ops.
void print_line(const char* program, const ops::MessageLine& line, const std::string& suffix = {});

// Prints the report's lines and returns its exit code. The first line gets advice_text and
// then `hint` (what only this app offers, e.g. i20's --passive).
int print_failure(const char* program, const ops::FailureReport& report, const std::string& hint = {});
// The same failure as one JSON object on stdout ({"type": "error", "outcome", "exit_code",
// "error", "lines"}), for --json callers (the Ansible modules): an error before or during a
// command is JSON too, not only text on stderr.
void print_failure_json(const ops::FailureReport& report);
// True when the command line asks for --json (for errors raised before it is parsed).
bool json_requested(int argc, char** argv);

// From a catch block when no session is open: prints the one line and returns the exit code.
int report_current_exception(const char* program);

}  // namespace i20::app
