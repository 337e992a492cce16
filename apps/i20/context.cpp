// SPDX-License-Identifier: GPL-2.0-or-later
#include "context.hpp"

#include <unistd.h>

#include <iostream>
#include <string>

#include "legacy_env.hpp"
#include "link/pipelined_link.hpp"

namespace i20::cli {

app::Session& Context::session() {
  if (!session_) {
    auto o = options;
    app::apply_legacy_environment(o, false);
    session_ = std::make_unique<app::Session>(std::move(o));
  }
  return *session_;
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

void Context::print_notes() {
  if (!options.verbose || !session_) return;
  for (const auto& note : session_->notes()) std::cerr << "note: " << note << "\n";
  if (const auto* pipelined = dynamic_cast<const link::PipelinedLink*>(session_->link_if_open())) {
    const auto& s = pipelined->statistics();
    std::cerr << "link: " << s.exchanges << " exchanges, " << s.commands << " commands, " << s.bursts
              << " bursts, " << s.bytes_sent << " bytes sent, " << s.bytes_received << " received, "
              << s.timeouts << " timeouts, " << s.crc_errors << " CRC errors, " << s.resyncs << " resyncs\n";
  }
}

}  // namespace i20::cli
