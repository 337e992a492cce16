// SPDX-License-Identifier: GPL-2.0-or-later
#include "legacy_env.hpp"

#include <cctype>
#include <cstdlib>
#include <string>

#include "lbp/error.hpp"

namespace i20::app {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

std::string trimmed_upper(std::string s) {
  std::string out;
  for (char c : s)
    if (!std::isspace(static_cast<unsigned char>(c))) out.push_back(static_cast<char>(std::toupper(c)));
  return out;
}

}  // namespace

void apply_legacy_environment(GlobalOptions& o, bool require_port) {
  const auto protocol = trimmed_upper(env("PROTOCOL"));
  if (!protocol.empty() && protocol != "LBP")
    throw UsageError("PROTOCOL is '" + env("PROTOCOL") + "' but the 8I20 speaks LBP: set PROTOCOL=LBP");
  if (o.has_target()) return;
  o.target.port = env("COMPORT");
  if (o.target.port.empty()) {
    if (!require_port) return;
    throw UsageError(
        "no port: set COMPORT (e.g. export COMPORT=/dev/ttyUSB0; `i20 ports` lists them) or pass --port, or --sim "
        "to try the built-in simulator");
  }
  if (const auto baud = env("BAUDRATE"); !baud.empty()) {
    std::size_t used = 0;
    unsigned long rate = 0;
    try {
      rate = std::stoul(baud, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != baud.size() || baud.find_first_not_of("0123456789") != std::string::npos || rate == 0 ||
        rate > 12000000)
      throw UsageError("BAUDRATE is '" + baud + "', not a baud rate: setup mode needs BAUDRATE=115200");
    o.link.baud = static_cast<unsigned>(rate);
  }
}

}  // namespace i20::app
