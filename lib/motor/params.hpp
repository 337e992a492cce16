// SPDX-License-Identifier: GPL-2.0-or-later
// A permanent-magnet synchronous motor described as data (a motor file, motors/*.yaml).
// SI units throughout; the loader (loader.hpp) reads them with their units.
#pragma once

#include <optional>
#include <string>

#include "motor/amp_gains.hpp"
#include "motor/sensors.hpp"

namespace i20::motor {

// What the motor drives (a motor file's `machine:`): a transmission to machine units, a load
// reflected to the motor shaft and, optionally, a compliant coupling to that load: two masses
// with one mechanical resonance. Without a stiffness the load is rigid on the shaft.
struct MachineParams {
  double lead_m_per_turn = 0;       // machine travel per motor turn (a 5 mm screw: 0.005); 0: not given
  double mass_kg = 0;               // moving mass on that lead, reflected as m (lead / 2 pi)^2
  double load_inertia_kgm2 = 0;     // a rotary load, reflected to the motor shaft
  double stiffness_nm_per_rad = 0;  // the coupling's, at the motor shaft; 0: rigid
  double damping_nm_per_rad_s = 0;  // the coupling's internal damping
};

struct MotorParams {
  std::string name;
  int pole_pairs = 0;
  WindingParams winding;                // per phase, line to neutral
  double torque_constant_nm_per_a = 0;  // torque per amp of the current vector (peak phase amps)
  double inertia_kgm2 = 0;              // the rotor plus whatever is rigidly on it (machine: the rest)
  double viscous_nm_per_rad_s = 0;
  double coulomb_nm = 0;             // dry friction: also the torque needed to break away
  double cogging_nm = 0;             // amplitude of the cogging torque
  int cogging_periods_per_turn = 0;  // its period: e.g. the slot count
  double load_nm =
      0;  // constant load torque (a vertical axis's weight), opposing forward rotation when positive
  double brake_torque_nm = 0;             // holding brake's capacity (0: no brake)
  bool brake_engaged = false;             // a holding brake holds when engaged (power off)
  std::optional<double> max_speed_rad_s;  // beyond it the model reports a runaway
  unsigned channel = 0;                   // the 8I20 channel (SSERIAL channel) it sits on
  std::optional<EncoderDescription> encoder;
  std::optional<HallDescription> halls;
  MachineParams machine;
};

// The machine's load reflected to the motor shaft: load inertia plus mass x (lead / 2 pi)^2.
double reflected_load_inertia(const MotorParams& params);
// What a rigid axis accelerates: the rotor and the reflected load.
double total_inertia(const MotorParams& params);
// Whether the load hangs on a spring (a stiffness and a load to hang): two masses.
bool compliant(const MotorParams& params);
// The coupling's resonance with the motor free (the two masses against each other):
// sqrt(k (1/J_motor + 1/J_load)) / 2 pi; empty for a rigid axis.
std::optional<double> resonance_hz(const MotorParams& params);

// The magnet's flux linkage (peak, per phase) that gives this torque constant. With peak
// phase currents (the amplitude-invariant dq frame), torque = 3/2 p psi i_q, so
// psi = Kt / (3/2 p); the back EMF on the q axis is w_e psi = (2/3) Kt w_m. Equivalently the
// back-EMF constant equals Kt in SI (V s/rad = N m/A) in the power-invariant frame; here
// 3/2 e_q i_q = T w_m holds exactly, which is what conserves energy.
double flux_linkage(const MotorParams& params);

// Throws MotorError naming the first value that makes no physical sense (non-positive R, L,
// Kt, inertia or pole pairs; negative friction, cogging or brake; ...).
void validate(const MotorParams& params);

}  // namespace i20::motor
