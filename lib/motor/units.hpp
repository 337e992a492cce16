// SPDX-License-Identifier: GPL-2.0-or-later
// The quantities of a motor file, with their units as the tool writes them everywhere
// ("0.6ohm", "1.75mH", "0.2Nm/A"). Resistance and inductance take params' unit table (the
// one `i20 set`, profiles and `i20 tune` read); the mechanical units are listed here. SI
// spelling, exact case; a space between number and unit is allowed.
#pragma once

#include <string>
#include <string_view>

namespace i20::motor {

enum class Quantity {
  Resistance,      // ohm, mohm
  Inductance,      // H, mH, uH
  TorqueConstant,  // Nm/A, mNm/A
  Inertia,         // kgm^2 (kg*m^2), kgcm^2 (kg*cm^2), gcm^2 (g*cm^2)
  Viscous,         // Nm/(rad/s) (Nms/rad), mNm/(rad/s), Nm/krpm, mNm/krpm
  Torque,          // Nm, mNm
  Speed,           // rpm, rad/s, rev/s
  Angle,           // deg, rad
  Stiffness,       // Nm/rad, kNm/rad, Nm/deg
  Length,          // mm, um, m, in
  Mass,            // kg, g
};

// The value in SI units (ohm, H, N m/A, kg m^2, N m s/rad, N m, rad/s, rad, N m/rad, m, kg). A sign is
// allowed (callers refuse what their key cannot be). Throws MotorError with one line:
// "1.75mh: unit 'mh' is not known; did you mean 'mH'?", "0.6: a resistance needs its unit
// (0.6ohm, 0.6mohm)".
double parse_quantity(Quantity kind, std::string_view text);

// "a torque is in Nm or mNm": the units of a kind, for messages and help.
std::string units_of(Quantity kind);

}  // namespace i20::motor
