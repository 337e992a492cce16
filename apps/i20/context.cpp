// SPDX-License-Identifier: GPL-2.0-or-later
#include "context.hpp"

#include <unistd.h>

#include <iostream>
#include <string>

#include "error/error.hpp"
#include "passive.hpp"
#include "terminal.hpp"

namespace i20::cli {

ops::Session& Context::session() {
  if (!session_) {
    ops::SessionOptions o = options;
    o.legacy = ops::LegacyEnvironment::IfNoTarget;
    session_ = std::make_unique<ops::Session>(std::move(o), app::stop_acknowledgement("i20"));
  }
  return *session_;
}

int Context::exit_code() const {
  if (comparison_ && *comparison_ != ops::Comparison::Same) return ops::exit_code(*comparison_);
  return ops::exit_code(outcome_);
}

void Context::settle() {
  if (!session_) return;
  const auto settled = session_->settle();
  if (settled.note) app::print_line("i20", *settled.note);
  record(settled.outcome);
}

int Context::report_failure() {
  const auto report = session_ ? session_->fail() : ops::failure_report_of_current_exception();
  if (options.json) app::print_failure_json(report);
  return app::print_failure("i20", report,
                            report.advice == ops::Advice::RunningHost ? passive_hint(*this) : "");
}

void Context::print_json(const app::Json& json) const {
  std::cout << json.dump() << "\n";
}

bool Context::confirm(const std::string& question) const {
  if (!isatty(STDIN_FILENO)) return false;
  std::cerr << question << " [y/N] " << std::flush;
  std::string answer;
  if (!std::getline(std::cin, answer)) return false;
  return answer == "y" || answer == "Y" || answer == "yes";
}

void Context::require_confirmation(const std::string& question, const std::string& refusal) const {
  if (!confirm(question)) throw UsageError(refusal);
}

void Context::print_notes() {
  if (!options.verbose || !session_) return;
  for (const auto& note : session_->notes()) std::cerr << "note: " << note << "\n";
}

}  // namespace i20::cli
