// SPDX-License-Identifier: GPL-2.0-or-later
#include "errors.hpp"

#include <iostream>

namespace i20::app {

namespace {
Overrides& program_overrides() {
  static Overrides overrides;
  return overrides;
}
}  // namespace

void set_overrides(const Overrides& overrides) {
  program_overrides() = overrides;
}

const Overrides& overrides() {
  return program_overrides();
}

std::string advice_text(ops::Advice advice) {
  const Overrides& has = overrides();
  switch (advice) {
    case ops::Advice::None: return {};
    case ops::Advice::RunningHost: return has.take_over ? " (--take-over)" : "";
    case ops::Advice::Force: return has.force ? "; pass --force to override" : "";
    case ops::Advice::AllowUnverified:
      return has.allow_unverified ? "; pass --allow-unverified if you know better" : "";
  }
  return {};
}

std::string with_advice(const std::string& message, ops::Advice advice) {
  std::string text = message;
  text.append(advice_text(advice));
  return text;
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
