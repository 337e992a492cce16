// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/quantity.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <utility>

#include "params/text.hpp"
#include "params/value.hpp"

namespace i20::profile {
namespace {

using params::trim;

// The unit each kind is converted to, as params::unit_symbols() names it.
const char* base_of(Quantity kind) {
  switch (kind) {
    case Quantity::Current: return "A";
    case Quantity::Resistance: return "ohm";
    case Quantity::Inductance: return "H";
    case Quantity::Voltage: return "V";
    case Quantity::Frequency: return "Hz";
  }
  return "";
}

const char* example_of(Quantity kind) {
  switch (kind) {
    case Quantity::Current: return "2.7A";
    case Quantity::Resistance: return "1.9ohm";
    case Quantity::Inductance: return "6.2mH";
    case Quantity::Voltage: return "170V";
    case Quantity::Frequency: return "500Hz";
  }
  return "";
}

// "2: a resistance needs its unit (2ohm, 2mohm)".
std::string missing_unit(Quantity kind, const std::string& typed) {
  std::string examples;
  for (const auto& u : params::unit_symbols())
    if (u.base == base_of(kind) && !u.alias)
      examples += (examples.empty() ? "" : ", ") + typed + std::string(u.symbol);
  return typed + ": " + params::quantity_name(base_of(kind)) + " needs its unit (" + examples + ")";
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
    why = t + ": not a number with a unit (e.g. " + example_of(kind) + ")";
    return std::nullopt;
  }
  const std::string_view rest = std::string_view(t).substr(number->length);
  if (rest.size() > 1 && rest[0] == ',' && std::isdigit(static_cast<unsigned char>(rest[1]))) {
    why = t + ": decimal comma: write the fraction with a point (e.g. " + example_of(kind) + ")";
    return std::nullopt;
  }
  const std::string unit = trim(rest);
  if (unit.empty()) {
    why = missing_unit(kind, t);
    return std::nullopt;
  }
  std::string unit_problem;
  const params::UnitSymbol* symbol = params::unit_of(unit, base_of(kind), unit_problem);
  if (!symbol) {
    why = t + ": " + unit_problem;
    return std::nullopt;
  }
  if (number->negative || number->is_zero()) {
    why = t + ": must be positive";
    return std::nullopt;
  }
  // Far outside anything a motor, supply or current loop has: the models downstream would overflow.
  const double value = number->to_double() * std::pow(10.0, symbol->power_of_ten);
  if (!(value >= kSmallest && value <= kLargest)) {
    why = t + ": out of range for a motor, supply or tuning value (" + format_si(kSmallest) + " .. " +
          format_si(kLargest) + " " + base_of(kind) + ")";
    return std::nullopt;
  }
  return value;
}

std::string format_quantity(Quantity kind, double si_value) {
  // Inductances read best in mH (servo motors: tenths to tens of mH); the rest in base units.
  const auto [number, unit] =
      kind == Quantity::Inductance ? std::pair{si_value * 1e3, "mH"} : std::pair{si_value, base_of(kind)};
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g %s", number, unit);
  return buf;
}

}  // namespace i20::profile
