// SPDX-License-Identifier: GPL-2.0-or-later
#include "motor/current_loop.hpp"

#include <cmath>
#include <complex>

namespace i20::motor {

Dq rotate(Dq v, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c * v.d - s * v.q, s * v.d + c * v.q};
}

double voltage_limit(double bus_voltage_v) {
  return bus_voltage_v / std::sqrt(3.0);
}

PiCurrentLoop::Output PiCurrentLoop::update(Dq e, const PhysicalGains& dg, const PhysicalGains& qg,
                                            double period, double vmax) {
  const Dq wanted{dg.kp_v_per_a * e.d + integral_.d, qg.kp_v_per_a * e.q + integral_.q};
  const double magnitude = std::hypot(wanted.d, wanted.q);
  Output out{wanted, false};
  if (magnitude > vmax) {
    out.limited = true;
    // One axis alone is clamped exactly (the scalar loop's std::clamp), else scaled.
    if (wanted.d == 0)
      out.voltage = {0, std::copysign(vmax, wanted.q)};
    else if (wanted.q == 0)
      out.voltage = {std::copysign(vmax, wanted.d), 0};
    else
      out.voltage = {wanted.d * vmax / magnitude, wanted.q * vmax / magnitude};
  }
  // Integrate only while unsaturated, or when the error pulls out of saturation.
  if (!out.limited || (e.d > 0) != (wanted.d > 0)) integral_.d += dg.ki_v_per_as * period * e.d;
  if (!out.limited || (e.q > 0) != (wanted.q > 0)) integral_.q += qg.ki_v_per_as * period * e.q;
  return out;
}

Winding::Winding(WindingParams params, double flux_linkage_vs) : params_(params), psi_(flux_linkage_vs) {}

void Winding::set_params(WindingParams params, double flux_linkage_vs) {
  params_ = params;
  psi_ = flux_linkage_vs;
  cached_dt_ = -1;
}

void Winding::step(Dq v, double omega_e, double dt) {
  const double r = params_.resistance_ohm, l = params_.inductance_h;
  if (dt != cached_dt_) {
    cached_dt_ = dt;
    cached_decay_ = std::exp(-r * dt / l);
  }
  const double a = cached_decay_;
  if (omega_e == 0) {  // the locked rotor: two independent R-L circuits
    const double b = (1.0 - a) / r;
    current_ = {a * current_.d + b * v.d, a * current_.q + b * v.q};
    return;
  }
  // As one complex equation (d real, q imaginary): L di/dt = u - z i, with
  // z = R + j w_e L and u = v - j w_e psi; i(dt) = u/z + (i - u/z) exp(-z dt / L).
  using C = std::complex<double>;
  const C z(r, omega_e * l);
  const C u(v.d, v.q - omega_e * psi_);
  const C steady = u / z;
  const C decay = a * std::polar(1.0, -omega_e * dt);
  const C i = steady + (C(current_.d, current_.q) - steady) * decay;
  current_ = {i.real(), i.imag()};
}

}  // namespace i20::motor
