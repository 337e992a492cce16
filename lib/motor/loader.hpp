// SPDX-License-Identifier: GPL-2.0-or-later
// Motor files (motors/*.yaml): a motor described as data, with units.
//
//   name: small servo              # optional
//   pole_pairs: 4
//   resistance: 0.6ohm             # per phase, line to neutral
//   inductance: 1.75mH             # per phase, line to neutral
//   torque_constant: 0.2Nm/A       # per amp of the current vector (peak phase amps)
//   inertia: 0.12kgcm^2
//   friction: {viscous: 0.02mNm/(rad/s), coulomb: 0.01Nm}     # optional
//   cogging: {torque: 0.005Nm, periods_per_turn: 24}           # optional
//   load: 0Nm                      # optional, + opposes forward rotation
//   brake: {torque: 1.3Nm, engaged: false}                     # optional
//   machine: {lead: 5mm, mass: 40kg, load_inertia: 0.2kgcm^2,   # optional: what it drives;
//             stiffness: 30Nm/rad, damping: 0.002Nm/(rad/s)}    # no stiffness: rigid
//   max_speed: 6000rpm             # optional: beyond it the virtual 8I20 faults
//   channel: 0                     # the 8I20 channel it sits on (default 0)
//   encoder: {counts_per_turn: 10000, direction: 1, index_angle: 0deg}   # optional
//   halls: {pattern: 25, polarity: active-high, inputs: [0, 1, 2]}       # optional, or
//   halls: {placement: 120, offset: 0deg, polarity: active-low, inputs: [3, 4, 5]}
//
// Errors are MotorError, one line: "motors/x.yaml:4: inductance: 1.75: an inductance needs
// its unit (1.75H, 1.75mH, 1.75uH)". Unknown and missing keys are errors.
#pragma once

#include <string>
#include <string_view>

#include "motor/params.hpp"

namespace i20::motor {

// The motor a file's text describes; `origin` names it in messages (a path).
MotorParams parse_motor(std::string_view yaml_text, std::string_view origin);

// The motor file at `path`, read with the checks every YAML file users hand the toolkit gets
// (a directory, a binary or a file over 1 MiB is refused before parsing): MotorError
// "PATH: reason".
MotorParams load_motor_file(const std::string& path);

// Sets one key (dotted for nested ones: "friction.viscous", "brake.engaged") from its text,
// as a motor file writes it: what the simulators' control lines change live. Throws
// MotorError "KEY: reason" and leaves `params` unchanged on error. `channel` cannot change
// live (`live` true).
void set_motor_key(MotorParams& params, std::string_view key, std::string_view value, bool live = false);

// The keys and their forms, one per line.
std::string motor_keys_help();

}  // namespace i20::motor
