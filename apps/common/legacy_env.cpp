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

void apply_legacy_environment(GlobalOptions& o) {
  const auto protocol = trimmed_upper(env("PROTOCOL"));
  if (!protocol.empty() && protocol != "LBP")
    throw UsageError("PROTOCOL is '" + env("PROTOCOL") + "' but the 8I20 speaks LBP: set PROTOCOL=LBP");
  const bool target_given = o.sim || !o.eth.empty() || !o.port.empty();
  if (target_given) return;
  o.port = env("COMPORT");
  if (o.port.empty())
    throw UsageError(
        "no port: set COMPORT (e.g. export COMPORT=/dev/ttyUSB0; `i20 ports` lists them) or pass --port, or "
        "--sim "
        "to try the built-in simulator");
  if (const auto baud = env("BAUDRATE"); !baud.empty()) {
    try {
      std::size_t used = 0;
      const unsigned long rate = std::stoul(baud, &used);
      if (used != baud.size() || rate == 0) throw std::invalid_argument(baud);
      o.baud = static_cast<unsigned>(rate);
    } catch (const std::exception&) {
      throw UsageError("BAUDRATE is '" + baud + "', not a number: setup mode needs BAUDRATE=115200");
    }
  }
}

}  // namespace i20::app
