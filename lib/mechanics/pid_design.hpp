// SPDX-License-Identifier: GPL-2.0-or-later
// Gains for LinuxCNC's pid, designed from an axis's identified mechanics (issue 43 item 3),
// as `i20 hal` wires the loop: pid.N.feedback is the encoder's position in machine units,
// pid.N.output the 8I20's current command in amps (bldc.N.value), at the servo period.
//
// The loop the design sees, per machine unit u and amp:
//
//   plant(s)  = Kt r / (J s^2 + B s) x current loop x hold x delay
//               (two masses when the rotor's inertia and a resonance are known: below)
//   current loop: 1 / (1 + s / w_cl)      (the 8I20's, from its tuning)
//   hold:         (1 - e^-sT) / sT         (the command held over the servo period)
//   delay:        e^-s tau                 (the read-to-write time inside the period; tau = T,
//                                           the whole period, is the conservative default)
//   pid(z)    = P + I T z / (z - 1) + D (1 - 1/z) / T   at z = e^{sT}: LinuxCNC's pid, whose
//               integral adds error x period each period and whose derivative is the
//               difference of two periods' errors over the period
//
// with r the machine units per motor radian (a 5 mm screw: 0.005 m / 2 pi). The design picks
// the highest crossover whose loop keeps at least the phase and gain margins asked for (45
// degrees, 8 dB by default) and, with only a resonance known, stays a fifth below it: the integral's zero a
// decade, the derivative's phase lead what the margin needs at that crossover. The margins
// are then measured on that loop over a frequency grid, not assumed.
//
// Two masses ring at the resonance with the motor alone carrying the loop's torque, so the
// loop's gain there is J_total / J_rotor times the rigid model's, lifted again by the
// coupling's sharpness (1 / 2 zeta): pid alone must cross over far below. A notch at the
// resonance (LinuxCNC's biquad on pid's output) takes that peak out: the design tries widths
// (q 0.5 to 2) and keeps the notch only where it lets the crossover rise, and then requires the
// margins with the resonance anywhere within +-10% of the figure given (an identified or data
// sheet figure is not exact, and a notch beside the peak is worse than none).
//
// Feedforward carries what the model knows: FF2 = J / (Kt r) (amps per u/s^2), FF1 = B / (Kt r)
// (amps per u/s), bias = G / Kt (a vertical axis's weight). Coulomb friction has no term in
// LinuxCNC's pid; the integral takes it.
#pragma once

#include <optional>
#include <string>

#include "mechanics/identify.hpp"

namespace i20::mechanics {

struct AxisModel {
  double inertia_kgm2 = 0;  // total, at the motor shaft
  double viscous_nm_per_rad_s = 0;
  double coulomb_nm = 0;
  double bias_nm = 0;  // + opposes forward motion
  double torque_constant_nm_per_a = 0;
  double units_per_rad = 0;  // machine units per motor radian (0.005 / 2 pi for a 5 mm screw in m)
  double max_current_a = 0;  // the 8I20's MAXCURRENT: pid's maxoutput
  std::optional<double> resonance_hz{};
  // With a resonance, the motor's own rotor inertia (its data sheet) makes the plant two
  // masses on a spring: the rotor, and the rest of the inertia behind a coupling that rings at
  // resonance_hz with this damping ratio (0.02 when unknown: a sharp peak, the safe side).
  // Above the anti-resonance the motor alone carries the loop's torque, so the loop's gain
  // there is J_total / J_rotor times what a rigid model says. 0: the rigid model.
  double rotor_inertia_kgm2 = 0;
  double coupling_damping_ratio = 0.02;
};

struct LoopTiming {
  double servo_period_s = 1e-3;
  double delay_s = 1e-3;               // feedback read to command written, within the period
  double current_bandwidth_hz = 1000;  // the 8I20's current loop
};

struct Margins {
  double phase_deg = 45;
  double gain_db = 8;
};

// A notch on pid's output, as LinuxCNC's biquad runs it each servo period with these
// coefficients given (its type 0): H(z) = (n0 + n1/z + n2/z^2) / (1 + d1/z + d2/z^2). Zero
// gain at `frequency_hz`, a band about frequency_hz / q wide (bilinear, prewarped there).
struct Notch {
  double frequency_hz = 0, q = 0;
  double n0 = 1, n1 = 0, n2 = 0, d1 = 0, d2 = 0;
};
// Throws IdentifyError unless 0 < frequency < the Nyquist rate and q > 0.
Notch notch_filter(double frequency_hz, double q, double servo_period_s);

struct PidGains {
  double p = 0, i = 0, d = 0, ff0 = 0, ff1 = 0, ff2 = 0, bias = 0, deadband = 0, maxoutput = 0;
  // A two-mass axis's resonance notched out of the loop, where that lets the crossover rise.
  std::optional<Notch> notch{};
  // What the design reached, measured on its loop model.
  double crossover_hz = 0;
  double phase_margin_deg = 0;
  double gain_margin_db = 0;
  std::string limited_by;  // what capped the crossover: "phase margin", "gain margin", "resonance", ...
};

// Throws IdentifyError when the model or timing cannot make a loop (non-positive inertia,
// torque constant, scale or period) or no crossover keeps the margins.
// Whether the design may put a notch after pid: only where the HAL has one (`i20 hal
// --notch`), or the loop LinuxCNC runs is not the loop designed.
enum class NotchUse { Never, WhereItHelps };
// How far off the figure given the resonance may lie while a notched design keeps its margins.
inline constexpr double kNotchResonanceSpread = 0.10;
PidGains design_pid(const AxisModel& axis, const LoopTiming& timing = {}, const Margins& wanted = {},
                    NotchUse notch = NotchUse::Never);

// The margins of LinuxCNC's pid with these gains (and their notch) on this axis as given: what
// design_pid reports for a design without a notch, for any gains (a check of hand-set or
// relay-found gains too). A notched design reports the worst within the resonance's spread.
Margins measure_margins(const AxisModel& axis, const LoopTiming& timing, const PidGains& gains,
                        double* crossover_hz = nullptr);

// The [JOINT_n] lines `i20 hal`'s file reads (P, I, D, FF0, FF1, FF2, BIAS, DEADBAND), with
// a comment of the design's margins; with a notch, its biquad coefficients as NOTCH_N0,
// NOTCH_N1, NOTCH_N2, NOTCH_D1, NOTCH_D2 (what `i20 hal --notch` reads).
std::string ini_section(int joint, const PidGains& gains);

}  // namespace i20::mechanics
