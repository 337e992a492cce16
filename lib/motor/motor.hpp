// SPDX-License-Identifier: GPL-2.0-or-later
// A permanent-magnet synchronous motor driven by an 8I20-like current loop, on the caller's
// clock. Pure: no I/O, no threads, no wall time.
//
//   Motor m(params);
//   m.command(drive);     // the current command and the loop's gains, held until changed
//   m.step(dt);           // time passes; the loop runs once per PWM period
//   m.state();            // angle, speed, currents, energies
//
// The loop samples the currents once per PWM period (12 kHz by default) and its voltage is
// applied during the next period (computation delay), as `i20 tune`'s model assumes; the
// winding and the rotor are integrated in `substeps` sub-steps of each period. Time given
// to step() that is not a whole number of periods is carried to the next call. See
// docs/motor-model.md for the equations.
#pragma once

#include <cstdint>
#include <optional>

#include "motor/current_loop.hpp"
#include "motor/params.hpp"

namespace i20::motor {

// What the amplifier asks of the motor for the coming periods.
struct DriveCommand {
  bool output_on = false;  // off: the bridge is off, no current flows, the rotor coasts
  // The controller's dq frame: its electrical angle (the 8I20's ANGLE), or, when
  // `frame_follows_rotor`, the rotor's own electrical angle sampled every period (ideal
  // commutation, for tests and benchmarks).
  double frame_angle_rad = 0;
  bool frame_follows_rotor = false;
  Dq current_a;  // the command in that frame
  PhysicalGains d_gains;
  PhysicalGains q_gains;
  double bus_voltage_v = 0;
  // The output switches off, and overcurrent() reports the phase, when a phase current
  // exceeds this (the 8I20: 125% of MAXCURRENT). 0: no trip.
  double phase_trip_a = 0;
};

// Energy bookkeeping since construction (joules), for balance checks.
struct EnergyLedger {
  double electrical_in = 0;    // 3/2 v.i delivered to the winding
  double copper_loss = 0;      // 3/2 R |i|^2
  double electromagnetic = 0;  // torque times angle: electrical -> mechanical
  double friction_loss = 0;    // Coulomb friction and holding brake
  double viscous_loss = 0;
  double load_work = 0;      // done against the load torque
  double cogging_work = 0;   // done against the cogging torque (conservative)
  double coupling_loss = 0;  // in a compliant coupling's damping
};

struct MotorState {
  double time_s = 0;
  double angle_turns = 0;  // mechanical, unwrapped; + is forward
  double speed_rad_s = 0;  // mechanical
  // The load (machine:): on a compliant coupling it lags or leads the rotor; on a rigid one
  // it is the rotor. Reflected to the motor shaft: turns and rad/s of the motor.
  double load_angle_turns = 0;
  double load_speed_rad_s = 0;
  double machine_position_m = 0;    // load turns x machine.lead (0 without a lead)
  double electrical_angle_rad = 0;  // pole_pairs x mechanical, wrapped to [0, 2 pi)
  Dq current_a;                     // rotor frame
  Dq voltage_v;                     // rotor frame, as applied during the last sub-step
  double phase_a[3] = {0, 0, 0};    // U, V, W
  double torque_nm = 0;             // electromagnetic
  bool stuck = false;               // held still by static friction or the brake
  bool voltage_limited = false;
  EnergyLedger energy;
};

// Feedback faults the simulators inject: a Hall code that no longer changes, an encoder
// whose count no longer changes (a cut cable or a lost supply).
struct SensorFaults {
  bool hall_stuck = false;
  bool encoder_lost = false;
};

// What the motor's encoder and Halls read now (faults applied); empty without the device.
struct SensorReading {
  std::optional<std::int64_t> encoder_count;
  std::optional<unsigned> hall_code;  // H1 H2 H3 in bits 2 1 0
};

class Motor {
 public:
  explicit Motor(MotorParams params, double pwm_hz = kDefaultPwmHz, int substeps = 4);

  void command(const DriveCommand& drive);
  const DriveCommand& drive() const { return drive_; }
  void step(double dt_s);

  const MotorState& state() const { return state_; }
  const MotorParams& params() const { return params_; }
  // Changes the motor live (load step, brake, friction, ...). Validated; the state stays.
  void set_params(const MotorParams& params);
  double period_s() const { return period_; }

  // Phases (bit 0 U, 1 V, 2 W) that tripped since the last call; the output went off then.
  unsigned take_overcurrent();
  // Whether the speed has exceeded max_speed since the last call.
  bool take_runaway();
  // The rotor's and the load's.
  double kinetic_energy_j() const;
  // Stored in a compliant coupling's spring: 1/2 k (angle - load angle)^2.
  double spring_energy_j() const;
  // Sensor faults freeze the reading at the moment they are switched on.
  void set_sensor_faults(SensorFaults faults);
  const SensorFaults& sensor_faults() const { return sensor_faults_; }
  // Where the sensors saw the shaft when they failed, in mechanical turns: the encoder's
  // turns, and the Halls' frozen electrical angle as turns of a shaft that gives it. Every
  // model of the card's inputs reads these while the fault is on (read_sensors() does).
  double encoder_frozen_turns() const { return encoder_frozen_turns_; }
  double hall_frozen_turns() const;
  SensorReading read_sensors() const;
  // Stored in the winding's inductance: 3/4 L |i|^2.
  double magnetic_energy_j() const;

 private:
  void run_period();
  void substep(Dq voltage_ab, double h);
  void advance_rotor(double torque_e, double h);
  void advance_motor(double torque_e, double external, double inertia, double h);
  void advance_load(double pull, double h);
  void update_outputs();
  void check_protection();

  MotorParams params_;
  double period_;
  int substeps_;
  Winding winding_;
  PiCurrentLoop loop_;
  DriveCommand drive_;
  MotorState state_;
  double angle_rad_ = 0;       // mechanical, unwrapped
  double load_angle_rad_ = 0;  // the load's, at the motor shaft; the rotor's when rigid
  double load_speed_ = 0;
  Dq applied_ab_;  // the voltage the bridge applies this period (stationary frame)
  double carry_s_ = 0;
  std::uint64_t periods_ = 0;
  unsigned overcurrent_ = 0;
  bool runaway_ = false;
  SensorFaults sensor_faults_;
  double encoder_frozen_turns_ = 0;
  double hall_frozen_electrical_ = 0;
};

}  // namespace i20::motor
