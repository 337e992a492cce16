// SPDX-License-Identifier: GPL-2.0-or-later
#include "errors.hpp"

#include <iostream>
#include <string_view>

#include "json.hpp"
#include "params/text.hpp"

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

void print_line(const char* program, const ops::MessageLine& line, const std::string& suffix) {
  // Messages echo what the user typed or a file held: never a raw control character.
  std::cerr << program << ": " << line.label << ": " << params::printable(line.message + suffix) << "\n";
}

int print_failure(const char* program, const ops::FailureReport& report, const std::string& hint) {
  for (std::size_t i = 0; i < report.lines.size(); ++i)
    print_line(program, report.lines[i], i == 0 ? advice_text(report.advice) + hint : "");
  return ops::exit_code(report.outcome);
}

void print_failure_json(const ops::FailureReport& report) {
  auto lines = Json::array();
  for (const auto& l : report.lines)
    lines.push(Json::object().set("label", l.label).set("message", params::printable(l.message)));
  auto j = Json::object();
  j.set("type", "error")
      .set("outcome", ops::to_string(report.outcome))
      .set("exit_code", ops::exit_code(report.outcome))
      .set("error", report.lines.empty() ? Json() : Json(params::printable(report.lines.front().message)))
      .set("lines", std::move(lines));
  std::cout << j.dump(0) << "\n" << std::flush;
}

bool json_requested(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string_view(argv[i]) == "--json") return true;
  return false;
}

int report_current_exception(const char* program) {
  return print_failure(program, ops::failure_report_of_current_exception());
}

}  // namespace i20::app
