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

void print_line(const char* program, const ops::ReportLine& line, const std::string& suffix) {
  std::cerr << program << ": " << line.label << ": " << line.message << suffix << "\n";
}

int print_failure(const char* program, const ops::FailureReport& report, const std::string& hint) {
  for (std::size_t i = 0; i < report.lines.size(); ++i)
    print_line(program, report.lines[i], i == 0 ? advice_text(report.advice) + hint : "");
  return ops::exit_code(report.outcome);
}

int report_current_exception(const char* program) {
  return print_failure(program, ops::failure_report_of_current_exception());
}

}  // namespace i20::app
