// SPDX-License-Identifier: GPL-2.0-or-later
#include "motor/units.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <vector>

#include "motor/error.hpp"
#include "params/text.hpp"
#include "params/value.hpp"

namespace i20::motor {
namespace {

struct MechanicalUnit {
  std::string_view symbol;
  Quantity kind;
  double to_si;
  bool alias = false;  // accepted, not listed
};

constexpr double kRpm = 2 * std::numbers::pi / 60;

const std::vector<MechanicalUnit>& mechanical_units() {
  static const std::vector<MechanicalUnit> table{
      {"Nm/A", Quantity::TorqueConstant, 1},
      {"mNm/A", Quantity::TorqueConstant, 1e-3},
      {"kgm^2", Quantity::Inertia, 1},
      {"kg*m^2", Quantity::Inertia, 1, true},
      {"kgcm^2", Quantity::Inertia, 1e-4},
      {"kg*cm^2", Quantity::Inertia, 1e-4, true},
      {"gcm^2", Quantity::Inertia, 1e-7},
      {"g*cm^2", Quantity::Inertia, 1e-7, true},
      {"Nm/(rad/s)", Quantity::Viscous, 1},
      {"Nms/rad", Quantity::Viscous, 1, true},
      {"mNm/(rad/s)", Quantity::Viscous, 1e-3},
      {"Nm/krpm", Quantity::Viscous, 1 / (1000 * kRpm)},
      {"mNm/krpm", Quantity::Viscous, 1e-3 / (1000 * kRpm)},
      {"Nm", Quantity::Torque, 1},
      {"mNm", Quantity::Torque, 1e-3},
      {"rpm", Quantity::Speed, kRpm},
      {"rad/s", Quantity::Speed, 1},
      {"rev/s", Quantity::Speed, 2 * std::numbers::pi},
      {"deg", Quantity::Angle, std::numbers::pi / 180},
      {"rad", Quantity::Angle, 1},
      {"Nm/rad", Quantity::Stiffness, 1},
      {"kNm/rad", Quantity::Stiffness, 1e3},
      {"Nm/deg", Quantity::Stiffness, 180 / std::numbers::pi},
      {"mm", Quantity::Length, 1e-3},
      {"um", Quantity::Length, 1e-6},
      {"m", Quantity::Length, 1},
      {"in", Quantity::Length, 0.0254},
      {"kg", Quantity::Mass, 1},
      {"g", Quantity::Mass, 1e-3},
  };
  return table;
}

const char* name_of(Quantity kind) {
  switch (kind) {
    case Quantity::Resistance: return "a resistance";
    case Quantity::Inductance: return "an inductance";
    case Quantity::TorqueConstant: return "a torque constant";
    case Quantity::Inertia: return "an inertia";
    case Quantity::Viscous: return "a viscous friction";
    case Quantity::Torque: return "a torque";
    case Quantity::Speed: return "a speed";
    case Quantity::Angle: return "an angle";
    case Quantity::Stiffness: return "a stiffness";
    case Quantity::Length: return "a length";
    case Quantity::Mass: return "a mass";
  }
  return "";
}

// Resistance and inductance: params' table, so "ohm" and "mH" mean what they mean elsewhere.
const char* params_base(Quantity kind) {
  return kind == Quantity::Resistance ? "ohm" : kind == Quantity::Inductance ? "H" : nullptr;
}

std::vector<std::string> listed_units(Quantity kind) {
  std::vector<std::string> out;
  if (const char* base = params_base(kind)) {
    for (const auto& u : params::unit_symbols())
      if (u.base == base && !u.alias) out.emplace_back(u.symbol);
    return out;
  }
  for (const auto& u : mechanical_units())
    if (u.kind == kind && !u.alias) out.emplace_back(u.symbol);
  return out;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

double mechanical_factor(Quantity kind, const std::string& unit, const std::string& text) {
  const auto& table = mechanical_units();
  const auto exact = std::ranges::find(table, unit, &MechanicalUnit::symbol);
  if (exact != table.end() && exact->kind == kind) return exact->to_si;
  if (exact != table.end()) throw MotorError(text + ": " + units_of(kind) + ", not " + unit);
  const auto similar = std::ranges::find_if(
      table, [&](const MechanicalUnit& u) { return u.kind == kind && iequals(u.symbol, unit); });
  if (similar != table.end())
    throw MotorError(text + ": unit '" + unit + "' is not known; did you mean '" +
                     std::string(similar->symbol) + "'?");
  throw MotorError(text + ": unit '" + unit + "' is not known (" + units_of(kind) + ")");
}

}  // namespace

std::string units_of(Quantity kind) {
  const auto units = listed_units(kind);
  std::string text = std::string(name_of(kind)) + " is in ";
  for (std::size_t i = 0; i < units.size(); ++i)
    text += (i == 0 ? "" : i + 1 == units.size() ? " or " : ", ") + units[i];
  return text;
}

double parse_quantity(Quantity kind, std::string_view raw) {
  const std::string text = params::trim(raw);
  const auto number = params::scan_decimal(text);
  if (!number) throw MotorError(text + ": not a number with a unit (" + units_of(kind) + ")");
  const std::string unit = params::trim(std::string_view(text).substr(number->length));
  if (unit.empty()) {
    std::string examples;
    for (const auto& u : listed_units(kind)) examples += (examples.empty() ? "" : ", ") + text + u;
    throw MotorError(text + ": " + name_of(kind) + " needs its unit (" + examples + ")");
  }
  const double value = number->to_double();
  double si = 0;
  if (const char* base = params_base(kind)) {
    std::string why;
    const params::UnitSymbol* symbol = params::unit_of(unit, base, why);
    if (!symbol) throw MotorError(text + ": " + why);
    si = value * std::pow(10.0, symbol->power_of_ten);
  } else {
    si = value * mechanical_factor(kind, unit, text);
  }
  if (!std::isfinite(si)) throw MotorError(text + ": out of range");
  return si;
}

}  // namespace i20::motor
