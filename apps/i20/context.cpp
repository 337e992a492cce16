#include "context.hpp"

#include <unistd.h>

#include <iostream>
#include <string>

namespace i20::cli {

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
}

}  // namespace i20::cli
