// SPDX-License-Identifier: GPL-2.0-or-later
#include "errors.hpp"

#include <iostream>

namespace i20::app {

std::string advice_text(ops::Advice advice) {
  switch (advice) {
    case ops::Advice::None: return {};
    case ops::Advice::RunningHost: return " (--take-over)";  // add_target_options defines it
  }
  return {};
}

int print_failure(const char* program, const ops::FailureReport& report, const std::string& hint) {
  for (std::size_t i = 0; i < report.lines.size(); ++i) {
    const auto& line = report.lines[i];
    std::cerr << program << ": " << line.label << ": " << line.message
              << (i == 0 ? advice_text(report.advice) + hint : "") << "\n";
  }
  return ops::exit_code(report.outcome);
}

int report_current_exception(const char* program) {
  const auto failure = ops::failure_of_current_exception();
  return print_failure(program, {failure.outcome, {failure.line}, failure.advice});
}

}  // namespace i20::app
