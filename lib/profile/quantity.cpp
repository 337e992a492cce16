#include "profile/quantity.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>
#include <vector>

#include "params/text.hpp"

namespace i20::profile {
namespace {

using params::iequals;
using params::trim;

struct Unit {
  const char* name;
  double factor;  // SI value = number * factor
};

std::vector<Unit> units_of(Quantity kind) {
  switch (kind) {
    case Quantity::Current: return {{"A", 1.0}, {"mA", 1e-3}};
    case Quantity::Resistance:
      return {{"ohm", 1.0}, {"ohms", 1.0}, {"\xCE\xA9", 1.0}, {"mohm", 1e-3}, {"m\xCE\xA9", 1e-3}};
    case Quantity::Inductance: return {{"H", 1.0}, {"mH", 1e-3}, {"uH", 1e-6}, {"\xC2\xB5H", 1e-6}};
    case Quantity::Voltage: return {{"V", 1.0}, {"mV", 1e-3}};
  }
  return {};
}

const char* example_of(Quantity kind) {
  switch (kind) {
    case Quantity::Current: return "2.7 A";
    case Quantity::Resistance: return "1.9 ohm";
    case Quantity::Inductance: return "6.2 mH";
    case Quantity::Voltage: return "170 V";
  }
  return "";
}

// Exact spelling first. Case is forgiven ("Ohm", "v") except on a leading m/M, where it
// would turn milli into mega.
std::optional<double> factor_of(Quantity kind, const std::string& unit) {
  for (const auto& u : units_of(kind))
    if (unit == u.name) return u.factor;
  if (unit.empty() || unit[0] == 'm' || unit[0] == 'M') return std::nullopt;
  for (const auto& u : units_of(kind))
    if (iequals(unit, u.name)) return u.factor;
  return std::nullopt;
}

}  // namespace

std::optional<double> parse_quantity(Quantity kind, std::string_view text, std::string& why) {
  const std::string t = trim(text);
  const char* begin = t.c_str();
  char* end = nullptr;
  const double number = std::strtod(begin, &end);
  if (end == begin) {
    why = "'" + t + "' is not a number with a unit (e.g. " + example_of(kind) + ")";
    return std::nullopt;
  }
  const std::string unit = trim(std::string_view(end));
  if (unit.empty()) {
    why = "'" + t + "' needs a unit (e.g. " + example_of(kind) + ")";
    return std::nullopt;
  }
  const auto factor = factor_of(kind, unit);
  if (!factor) {
    std::string list;
    for (const auto& u : units_of(kind)) list += (list.empty() ? "" : ", ") + std::string(u.name);
    why = "'" + unit + "' is not a unit for this value (use " + list + ")";
    return std::nullopt;
  }
  const double value = number * *factor;
  if (!std::isfinite(value) || value <= 0) {
    why = "'" + t + "' must be positive";
    return std::nullopt;
  }
  return value;
}

std::string format_quantity(Quantity kind, double si_value) {
  // Inductances read best in mH (servo motors: tenths to tens of mH); the rest in base units.
  const auto [number, unit] = kind == Quantity::Inductance ? std::pair{si_value * 1e3, "mH"}
                              : kind == Quantity::Current  ? std::pair{si_value, "A"}
                              : kind == Quantity::Voltage  ? std::pair{si_value, "V"}
                                                           : std::pair{si_value, "ohm"};
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g %s", number, unit);
  return buf;
}

}  // namespace i20::profile
