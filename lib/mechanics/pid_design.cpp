// SPDX-License-Identifier: GPL-2.0-or-later
#include "mechanics/pid_design.hpp"

#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

namespace i20::mechanics {
namespace {

using Complex = std::complex<double>;
constexpr double kPi = std::numbers::pi;
constexpr double kTwoPi = 2 * kPi;

// The integral's zero sits this far below the crossover: it removes the static error (a
// bias guessed wrong, Coulomb friction) without eating the phase margin.
constexpr double kIntegralDecade = 10;
// More lead than this from the derivative asks for a D that amplifies the encoder's steps.
constexpr double kMostLeadDeg = 70;
// Below a known resonance by this factor when only the resonance is known (no rotor inertia
// to model the two masses): the rigid-body model holds there.
constexpr double kBelowResonance = 5;
// The grid the margins are read on: log-spaced from 0.05 Hz to the Nyquist rate.
constexpr int kGridPoints = 3000;
// A notch's widths tried (its q: centre frequency over width).
constexpr double kNotchWidths[] = {0.5, 0.7, 1.0, 1.4, 2.0};

double degrees(double radians) {
  return radians * 180 / kPi;
}

void require_model(const AxisModel& a, const LoopTiming& t) {
  const auto positive = [](double v) { return v > 0 && std::isfinite(v); };
  if (!positive(a.inertia_kgm2)) throw IdentifyError("a pid needs a positive inertia");
  if (!positive(a.torque_constant_nm_per_a)) throw IdentifyError("a pid needs a positive torque constant");
  if (!positive(a.units_per_rad)) throw IdentifyError("a pid needs the machine units per motor radian");
  if (!positive(t.servo_period_s)) throw IdentifyError("a pid needs a positive servo period");
  if (!(t.delay_s >= 0) || !positive(t.current_bandwidth_hz))
    throw IdentifyError("a pid needs a delay of 0 or more and a positive current-loop bandwidth");
}

// Whether the plant is two masses: a resonance, and a rotor lighter than the whole.
bool two_masses(const AxisModel& a) {
  return a.resonance_hz && a.rotor_inertia_kgm2 > 0 && a.rotor_inertia_kgm2 < a.inertia_kgm2;
}

// The motor's angle per torque. Rigid: 1 / (J s^2 + B s). Two masses (rotor J_m with the
// viscous friction, the rest J_l behind a spring k with damping c):
//   1 / (J_m s^2 + B s + (k + c s) J_l s^2 / (J_l s^2 + c s + k))
// with k and c from the resonance (the rotor free) and the damping ratio.
Complex motor_angle_per_torque(const AxisModel& a, Complex s) {
  if (!two_masses(a)) return 1.0 / (a.inertia_kgm2 * s * s + a.viscous_nm_per_rad_s * s);
  const double jm = a.rotor_inertia_kgm2, jl = a.inertia_kgm2 - jm;
  const double mobility = 1 / jm + 1 / jl;
  const double w_r = kTwoPi * *a.resonance_hz;
  const double k = w_r * w_r / mobility;
  const double c = 2 * a.coupling_damping_ratio * std::sqrt(k / mobility);
  const Complex spring = k + c * s;
  return 1.0 / (jm * s * s + a.viscous_nm_per_rad_s * s + spring * jl * s * s / (jl * s * s + c * s + k));
}

// Current (A) to position (machine units) at w rad/s, with the hold, the delay and the 8I20's
// current loop.
Complex plant(const AxisModel& a, const LoopTiming& t, double w) {
  const Complex s{0, w};
  const double T = t.servo_period_s;
  const Complex mechanics = a.torque_constant_nm_per_a * a.units_per_rad * motor_angle_per_torque(a, s);
  const Complex current = 1.0 / (1.0 + s / (kTwoPi * t.current_bandwidth_hz));
  const Complex hold = (1.0 - std::exp(-s * T)) / (s * T);
  return mechanics * current * hold * std::exp(-s * t.delay_s);
}

Complex notch_response(const std::optional<Notch>& n, double T, double w) {
  if (!n) return 1;
  const Complex zi = std::exp(Complex{0, -w * T});  // 1 / z
  return (n->n0 + n->n1 * zi + n->n2 * zi * zi) / (1.0 + n->d1 * zi + n->d2 * zi * zi);
}

// LinuxCNC's pid at z = e^{jwT} (feedback terms only; feedforward is outside the loop), and
// the notch after it.
Complex pid(const PidGains& g, double T, double w) {
  const Complex z = std::exp(Complex{0, w * T});
  return (g.p + g.i * T * z / (z - 1.0) + g.d * (1.0 - 1.0 / z) / T) * notch_response(g.notch, T, w);
}

struct Reading {
  double crossover_rad_s = 0;
  Margins margins;
};

// The loop's phase, unwrapped from the lowest frequency up; the margins at its last gain
// crossover and at the first -180 crossing above it.
Reading read_margins(const AxisModel& a, const LoopTiming& t, const PidGains& g) {
  const double lowest = kTwoPi * 0.05, nyquist = kPi / t.servo_period_s;
  std::vector<double> w(kGridPoints), magnitude(kGridPoints), phase(kGridPoints);
  double previous = 0;
  for (int k = 0; k < kGridPoints; ++k) {
    w[k] = lowest * std::pow(nyquist * 0.999 / lowest, static_cast<double>(k) / (kGridPoints - 1));
    const Complex loop = pid(g, t.servo_period_s, w[k]) * plant(a, t, w[k]);
    magnitude[k] = std::abs(loop);
    double p = std::arg(loop);
    if (k > 0)
      while (p - previous > kPi) p -= 2 * kPi;
    if (k > 0)
      while (p - previous < -kPi) p += 2 * kPi;
    phase[k] = previous = p;
  }
  // The phase at low frequency is about -270 degrees (two integrators of the mechanics and
  // the pid's): shift by whole turns so it reads so.
  const double turns = std::round((phase[0] + 1.5 * kPi) / (2 * kPi));
  for (auto& p : phase) p -= turns * 2 * kPi;
  // Margins over the whole response, not at one crossover: a resonance can lift the gain
  // through 1 again, or past an odd multiple of -180 degrees, above the main crossover.
  const auto at = [&](const std::vector<double>& v, int k, double h) {
    return v[k - 1] + h * (v[k] - v[k - 1]);
  };
  Reading r;
  int first = -1;  // the main crossover: the gain falls through 1 (the integrators hold it up below)
  for (int k = 1; k < kGridPoints && first < 0; ++k)
    if (magnitude[k - 1] >= 1 && magnitude[k] < 1) first = k;
  if (first < 0) {
    r.margins = {-180, -100};
    return r;
  }
  const double f = (magnitude[first - 1] - 1) / (magnitude[first - 1] - magnitude[first]);
  r.crossover_rad_s = at(w, first, f);
  r.margins.phase_deg = 180;
  r.margins.gain_db = 100;  // no -180 crossing below Nyquist: as good as unbounded
  for (int k = first; k < kGridPoints; ++k) {
    if ((magnitude[k - 1] >= 1) != (magnitude[k] >= 1)) {  // every gain crossing
      const double h = (magnitude[k - 1] - 1) / (magnitude[k - 1] - magnitude[k]);
      double wrapped = std::fmod(at(phase, k, h), 2 * kPi);  // into (-360, 0] degrees
      if (wrapped > 0) wrapped -= 2 * kPi;
      r.margins.phase_deg = std::min(r.margins.phase_deg, degrees(wrapped + kPi));
    }
    const double turn_before = std::floor((phase[k - 1] + kPi) / (2 * kPi));
    const double turn_after = std::floor((phase[k] + kPi) / (2 * kPi));
    if (turn_before != turn_after) {  // the phase passed an odd multiple of -180 degrees
      const double edge = std::max(turn_before, turn_after) * 2 * kPi - kPi;
      const double h = (phase[k - 1] - edge) / (phase[k - 1] - phase[k]);
      r.margins.gain_db = std::min(r.margins.gain_db, -20 * std::log10(at(magnitude, k, h)));
    }
  }
  return r;
}

// With a notch, the worst margins with the resonance anywhere within the spread of the
// figure given (its ends and the figure itself); the crossover is the figure's.
Reading read_margins_robustly(const AxisModel& a, const LoopTiming& t, const PidGains& g) {
  Reading r = read_margins(a, t, g);
  if (!g.notch || !two_masses(a)) return r;
  for (const double scale : {1 - kNotchResonanceSpread, 1 + kNotchResonanceSpread}) {
    AxisModel shifted = a;
    shifted.resonance_hz = *a.resonance_hz * scale;
    const Reading other = read_margins(shifted, t, g);
    r.margins.phase_deg = std::min(r.margins.phase_deg, other.margins.phase_deg);
    r.margins.gain_db = std::min(r.margins.gain_db, other.margins.gain_db);
  }
  return r;
}

// The pid for a crossover at w: the integral a decade below, the derivative's lead what the
// wanted phase margin needs (plus a little for the grid), P for unit loop gain at w.
std::optional<PidGains> shaped_for(const AxisModel& a, const LoopTiming& t, const Margins& wanted, double w,
                                   const std::optional<Notch>& notch) {
  // about -180 - delay at low w; the notch's lag below its centre adds to it
  const double plant_phase = std::arg(plant(a, t, w) * notch_response(notch, t.servo_period_s, w));
  double lead = wanted.phase_deg + 3 - 180 - degrees(plant_phase);
  while (lead > 180) lead -= 360;
  while (lead < -180) lead += 360;
  const double integral_lag = degrees(std::atan(1 / kIntegralDecade));
  const double needed = lead + integral_lag;
  if (needed > kMostLeadDeg) return std::nullopt;
  PidGains g;
  g.notch = notch;
  const double wi = w / kIntegralDecade;
  const double d_over_p = (std::tan(needed * kPi / 180) + wi / w) / w;
  g.p = 1;
  g.i = wi;
  g.d = std::max(0.0, d_over_p);
  const double loop = std::abs(pid(g, t.servo_period_s, w) * plant(a, t, w));
  g.p /= loop;
  g.i /= loop;
  g.d /= loop;
  return g;
}

// The highest crossover up to `highest` rad/s whose loop (with `notch`) keeps the margins;
// `limited_by` says what stopped the climb.
std::optional<PidGains> highest_crossover(const AxisModel& axis, const LoopTiming& timing,
                                          const Margins& wanted, double highest,
                                          const std::optional<Notch>& notch, std::string& limited_by) {
  std::optional<PidGains> best;
  const std::string cap = limited_by;
  for (double w = kTwoPi * 0.5; w <= highest; w *= 1.02) {
    auto g = shaped_for(axis, timing, wanted, w, notch);
    if (!g) {
      limited_by = "the derivative's lead";
      break;
    }
    const Reading r = read_margins_robustly(axis, timing, *g);
    if (r.margins.phase_deg < wanted.phase_deg) {
      limited_by = "the phase margin";
      if (best) break;
      continue;
    }
    if (r.margins.gain_db < wanted.gain_db) {
      limited_by = "the gain margin";
      if (best) break;
      continue;
    }
    g->crossover_hz = r.crossover_rad_s / kTwoPi;
    g->phase_margin_deg = r.margins.phase_deg;
    g->gain_margin_db = r.margins.gain_db;
    best = g;
    limited_by = cap;
  }
  return best;
}

}  // namespace

Notch notch_filter(double frequency_hz, double q, double servo_period_s) {
  if (!(servo_period_s > 0) || !(frequency_hz > 0 && frequency_hz < 0.5 / servo_period_s) || !(q > 0))
    throw IdentifyError("a notch needs a centre frequency between 0 and half the servo rate, and a width");
  const double w0 = kTwoPi * frequency_hz * servo_period_s;
  const double alpha = std::sin(w0) / (2 * q), a0 = 1 + alpha;
  Notch n{.frequency_hz = frequency_hz, .q = q};
  n.n0 = n.n2 = 1 / a0;
  n.n1 = n.d1 = -2 * std::cos(w0) / a0;
  n.d2 = (1 - alpha) / a0;
  return n;
}

Margins measure_margins(const AxisModel& axis, const LoopTiming& timing, const PidGains& gains,
                        double* crossover_hz) {
  require_model(axis, timing);
  const Reading r = read_margins(axis, timing, gains);
  if (crossover_hz) *crossover_hz = r.crossover_rad_s / kTwoPi;
  return r.margins;
}

PidGains design_pid(const AxisModel& axis, const LoopTiming& timing, const Margins& wanted,
                    NotchUse notch_use) {
  require_model(axis, timing);
  double highest = 0.25 * kPi / timing.servo_period_s;  // a quarter of Nyquist
  std::string cap = "the servo period";
  // A rigid model holds only well below a resonance; a two-mass model is judged on its own
  // frequency response (the margins read off the grid see the peak).
  if (axis.resonance_hz && !two_masses(axis) && kTwoPi * *axis.resonance_hz / kBelowResonance < highest) {
    highest = kTwoPi * *axis.resonance_hz / kBelowResonance;
    cap = "the resonance";
  }
  std::string limited_by = cap;
  auto best = highest_crossover(axis, timing, wanted, highest, std::nullopt, limited_by);
  const double nyquist_hz = 0.5 / timing.servo_period_s;
  if (notch_use == NotchUse::WhereItHelps && two_masses(axis) &&
      *axis.resonance_hz * (1 + kNotchResonanceSpread) < nyquist_hz)
    for (const double q : kNotchWidths) {
      std::string notched_limit = cap;
      auto notched =
          highest_crossover(axis, timing, wanted, highest,
                            notch_filter(*axis.resonance_hz, q, timing.servo_period_s), notched_limit);
      if (notched && (!best || notched->crossover_hz > best->crossover_hz)) {
        best = notched;
        limited_by = notched_limit;
      }
    }
  if (!best)
    throw IdentifyError("no crossover keeps " + std::to_string(static_cast<int>(wanted.phase_deg)) +
                        " degrees and " + std::to_string(static_cast<int>(wanted.gain_db)) +
                        " dB on this axis at this servo period (limited by " + limited_by + ")");
  const double amps_per_nm_unit = 1 / (axis.torque_constant_nm_per_a * axis.units_per_rad);
  best->ff1 = axis.viscous_nm_per_rad_s * amps_per_nm_unit;
  best->ff2 = axis.inertia_kgm2 * amps_per_nm_unit;
  best->bias = axis.bias_nm / axis.torque_constant_nm_per_a;
  best->maxoutput = axis.max_current_a;
  best->limited_by = limited_by;
  return *best;
}

std::string ini_section(int joint, const PidGains& g) {
  char buf[1280];
  std::snprintf(buf, sizeof buf,
                "[JOINT_%d]\n"
                "# i20: crossover %.1f Hz, phase margin %.0f degrees, gain margin %.1f dB (limited by %s);\n"
                "# the pid's output is the 8I20's current in amps, its feedback in machine units\n"
                "P = %.6g\nI = %.6g\nD = %.6g\nFF0 = 0\nFF1 = %.6g\nFF2 = %.6g\nBIAS = %.6g\nDEADBAND = 0\n",
                joint, g.crossover_hz, g.phase_margin_deg, g.gain_margin_db, g.limited_by.c_str(), g.p, g.i,
                g.d, g.ff1, g.ff2, g.bias);
  std::string section = buf;
  if (g.notch) {
    std::snprintf(buf, sizeof buf,
                  "# the notch after pid (i20 hal --notch wires LinuxCNC's biquad, type 0): %.1f Hz, q %.2f\n"
                  "NOTCH_N0 = %.9g\nNOTCH_N1 = %.9g\nNOTCH_N2 = %.9g\nNOTCH_D1 = %.9g\nNOTCH_D2 = %.9g\n",
                  g.notch->frequency_hz, g.notch->q, g.notch->n0, g.notch->n1, g.notch->n2, g.notch->d1,
                  g.notch->d2);
    section += buf;
  }
  return section;
}

}  // namespace i20::mechanics
