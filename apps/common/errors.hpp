// SPDX-License-Identifier: GPL-2.0-or-later
// How the apps print what went wrong: one line per report line, "PROGRAM: LABEL: MESSAGE", on
// stderr. What a failure means and its exit code are lib/ops's (ops::Session::fail,
// ops::failure_of_current_exception, ops::exit_code); no app decides either.
#pragma once

#include <string>

#include "ops/session.hpp"
#include "parse_error.hpp"

namespace i20::app {

// The global option that changes the failure's outcome, as every app names it (added to the
// first line): " (--take-over)" beside a running host; empty for none.
std::string advice_text(ops::Advice advice);

// "PROGRAM: LABEL: MESSAGE[SUFFIX]" on stderr: every line the apps print from lib/ops.
void print_line(const char* program, const ops::ReportLine& line, const std::string& suffix = {});

// Prints the report's lines and returns its exit code. The first line gets advice_text and
// then `hint` (what only this app offers, e.g. i20's --passive).
int print_failure(const char* program, const ops::FailureReport& report, const std::string& hint = {});

// From a catch block when no session is open: prints the one line and returns the exit code.
int report_current_exception(const char* program);

}  // namespace i20::app
