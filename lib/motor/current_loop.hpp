// SPDX-License-Identifier: GPL-2.0-or-later
// The 8I20's current loop and the motor's winding, in a dq frame: the one implementation
// behind `i20 tune`'s simulated step (lib/profile/step_response) and the virtual 8I20's
// motor (lib/sim). Currents and voltages are peak phase quantities (the amplitude-invariant
// dq transform): |i_dq| is the peak phase current, |v_dq| the peak phase voltage.
#pragma once

#include "motor/amp_gains.hpp"

namespace i20::motor {

struct Dq {
  double d = 0;
  double q = 0;
};

// Rotates a vector by `angle` (radians): frame changes between the card's frame, the
// stationary (alpha-beta) frame and the rotor's.
Dq rotate(Dq v, double angle);

// The largest phase voltage space-vector PWM makes from a bus: Vbus / sqrt(3).
double voltage_limit(double bus_voltage_v);

// The PI current controller of both axes, sampled once per period. The output vector is
// limited to |v| <= vmax; an axis's integrator stops while the output is limited, unless
// its error pulls the output out of the limit (anti-windup).
class PiCurrentLoop {
 public:
  struct Output {
    Dq voltage;
    bool limited = false;
  };
  Output update(Dq error, const PhysicalGains& d_gains, const PhysicalGains& q_gains, double period_s,
                double vmax);
  void reset() { integral_ = {}; }

 private:
  Dq integral_;
};

// The winding of a PMSM in the rotor's dq frame (d along the magnet's flux):
//   L di_d/dt = v_d - R i_d + w_e L i_q
//   L di_q/dt = v_q - R i_q - w_e L i_d - w_e psi
// with w_e the electrical speed and psi the magnet's flux linkage (peak, per phase). Over a
// step with v and w_e held, solved exactly (complex exponential), so a locked rotor is the
// exact zero-order-hold R-L response i' = a i + (1 - a) v / R, a = exp(-R dt / L).
class Winding {
 public:
  Winding(WindingParams params, double flux_linkage_vs);
  void step(Dq voltage, double omega_e, double dt_s);
  Dq current() const { return current_; }
  void set_current(Dq current) { current_ = current; }
  const WindingParams& params() const { return params_; }
  void set_params(WindingParams params, double flux_linkage_vs);
  double flux_linkage_vs() const { return psi_; }

 private:
  WindingParams params_;
  double psi_ = 0;
  Dq current_;
  // exp(-R dt / L) for the last dt, which is nearly always the same.
  double cached_dt_ = -1;
  double cached_decay_ = 0;
};

}  // namespace i20::motor
