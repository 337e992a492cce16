// SPDX-License-Identifier: GPL-2.0-or-later
// How the apps print what went wrong: one line per report line, "PROGRAM: LABEL: MESSAGE", on
// stderr. What a failure means and its exit code are lib/ops's (ops::Session::fail,
// ops::failure_of_current_exception, ops::exit_code); no app decides either.
#pragma once

#include <string>

#include "ops/session.hpp"
#include "parse_error.hpp"

namespace i20::app {

// Prints the report's lines and returns its exit code. `hint` is appended to the first
// line's message (the flag that changes the outcome, which only the app can name).
int print_failure(const char* program, const ops::FailureReport& report, const std::string& hint = {});

// From a catch block when no session is open: prints the one line and returns the exit code.
int report_current_exception(const char* program);

}  // namespace i20::app
