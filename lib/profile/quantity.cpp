// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/quantity.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "params/text.hpp"
#include "params/value.hpp"

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

constexpr double kSmallest = 1e-9;
constexpr double kLargest = 1e9;

std::string format_si(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::optional<double> parse_quantity(Quantity kind, std::string_view text, std::string& why) {
  const std::string t = trim(text);
  // The value parser's number syntax: one sign, a decimal point, an exponent; no NaN,
  // infinity or hexadecimal fractions, which strtod would take.
  const auto number = params::scan_decimal(t);
  if (!number) {
    why = "'" + t + "' is not a number with a unit (e.g. " + example_of(kind) + ")";
    return std::nullopt;
  }
  const std::string_view rest = std::string_view(t).substr(number->length);
  if (rest.size() > 1 && rest[0] == ',' && std::isdigit(static_cast<unsigned char>(rest[1]))) {
    why = "'" + t + "' has a decimal comma; write the fraction with a point (e.g. " + example_of(kind) + ")";
    return std::nullopt;
  }
  const std::string unit = trim(rest);
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
  if (number->negative || number->is_zero()) {
    why = "'" + t + "' must be positive";
    return std::nullopt;
  }
  // Far outside anything a motor or supply has: the models downstream would overflow.
  const double value = number->to_double() * *factor;
  if (!(value >= kSmallest && value <= kLargest)) {
    why = "'" + t + "' is out of range for a motor or supply value (" + format_si(kSmallest) + " .. " +
          format_si(kLargest) + " in " + units_of(kind).front().name + ")";
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
