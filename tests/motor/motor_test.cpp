// SPDX-License-Identifier: GPL-2.0-or-later
// The motor model against closed-form physics: steady-state speed under a constant torque
// with viscous and Coulomb friction, energy balance, back EMF limiting the current, static
// friction and the brake holding, and the loop's protection.
#include "motor/motor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "motor/error.hpp"

using namespace i20::motor;

namespace {

// The small servo: 4 pole pairs, 0.6 ohm, 1.75 mH, 0.2 Nm/A.
MotorParams servo() {
  MotorParams p;
  p.pole_pairs = 4;
  p.winding = {0.6, 1.75e-3};
  p.torque_constant_nm_per_a = 0.2;
  p.inertia_kgm2 = 1.2e-5;
  p.viscous_nm_per_rad_s = 1e-3;
  p.coulomb_nm = 0.02;
  return p;
}

// Gains tuned for the winding at 500 Hz (pole-zero cancellation), on a 320 V bus.
DriveCommand follow(double iq, double bus = 320.0) {
  const double wc = 2 * std::numbers::pi * 500;
  DriveCommand d;
  d.output_on = true;
  d.frame_follows_rotor = true;
  d.current_a = {0, iq};
  d.d_gains = d.q_gains = {1.75e-3 * wc, 0.6 * wc};
  d.bus_voltage_v = bus;
  return d;
}

}  // namespace

TEST(MotorMechanics, SteadySpeedUnderAConstantTorqueIsTheClosedForm) {
  // No drive; a constant torque from the load (negative: it drives forward).
  MotorParams p = servo();
  p.load_nm = -0.3;
  Motor m(p);
  m.step(0.2);  // 16 mechanical time constants (J/B = 12 ms)
  const double expected = (0.3 - p.coulomb_nm) / p.viscous_nm_per_rad_s;  // 280 rad/s
  EXPECT_NEAR(m.state().speed_rad_s, expected, 1e-6 * expected);
  // And the closed-form approach: w(t) = w_ss (1 - exp(-B t / J)) after one time constant.
  Motor early(p);
  early.step(0.012);
  EXPECT_NEAR(early.state().speed_rad_s, expected * (1 - std::exp(-1.0)), 0.005 * expected);
}

TEST(MotorMechanics, SteadySpeedUnderTheCurrentLoopIsTheClosedForm) {
  Motor m(servo());
  m.command(follow(2.0));  // 0.4 Nm
  m.step(0.25);
  const double expected = (0.2 * 2.0 - 0.02) / 1e-3;  // 380 rad/s, 3630 rpm
  EXPECT_NEAR(m.state().speed_rad_s, expected, 0.002 * expected);
  EXPECT_NEAR(m.state().current_a.q, 2.0, 0.01);
  EXPECT_NEAR(m.state().current_a.d, 0.0, 0.01);
}

TEST(MotorMechanics, StaticFrictionHoldsBelowBreakaway) {
  Motor m(servo());
  m.command(follow(0.09));  // 0.018 Nm < 0.02 Nm Coulomb
  m.step(0.1);
  EXPECT_EQ(m.state().speed_rad_s, 0.0);
  EXPECT_EQ(m.state().angle_turns, 0.0);
  EXPECT_TRUE(m.state().stuck);
  m.command(follow(0.11));  // 0.022 Nm: breaks away
  m.step(0.1);
  EXPECT_GT(m.state().speed_rad_s, 0.0);
}

TEST(MotorMechanics, AFrictionStoppedRotorStaysStopped) {
  MotorParams p = servo();
  p.load_nm = -0.3;
  Motor m(p);
  m.step(0.05);
  ASSERT_GT(m.state().speed_rad_s, 100);
  p.load_nm = 0;  // the driving torque goes away: viscous and Coulomb friction stop it
  m.set_params(p);
  m.step(0.5);
  EXPECT_EQ(m.state().speed_rad_s, 0.0);
  EXPECT_TRUE(m.state().stuck);
}

TEST(MotorMechanics, AnEngagedBrakeHoldsUpToItsTorque) {
  MotorParams p = servo();
  p.brake_torque_nm = 1.0;
  p.brake_engaged = true;
  Motor m(p);
  m.command(follow(4.0));  // 0.8 Nm < 1.02 Nm
  m.step(0.05);
  EXPECT_EQ(m.state().speed_rad_s, 0.0);
  p.brake_engaged = false;
  m.set_params(p);
  m.step(0.05);
  EXPECT_GT(m.state().speed_rad_s, 10.0);
}

TEST(MotorMechanics, CoggingHasItsOwnPeriod) {
  // Cogging alone: a rotor released near a detent settles in one, at a multiple of 1/N turn.
  MotorParams p = servo();
  p.coulomb_nm = 0;
  p.cogging_nm = 0.05;
  p.cogging_periods_per_turn = 24;
  p.load_nm = 0.02;  // pushes it off the detent at 0 backwards a little
  Motor m(p);
  m.step(1.0);
  const double angle = m.state().angle_turns * 24;  // in cogging periods
  // Equilibrium: -A sin(N theta) = load, theta = -asin(load / A) / N.
  EXPECT_NEAR(angle * 2 * std::numbers::pi, -std::asin(0.02 / 0.05), 1e-3);
}

TEST(MotorEnergy, WorkInIsKineticPlusLossesWhileAccelerating) {
  MotorParams p = servo();
  Motor m(p);
  m.command(follow(3.0));
  m.step(0.03);  // still accelerating: the kinetic energy matters
  const auto& e = m.state().energy;
  ASSERT_GT(m.kinetic_energy_j(), 0.2 * e.electromagnetic);
  // Mechanical side: electromagnetic work = kinetic + friction + viscous + load + cogging.
  const double mechanical =
      m.kinetic_energy_j() + e.friction_loss + e.viscous_loss + e.load_work + e.cogging_work;
  EXPECT_NEAR(mechanical, e.electromagnetic, 1e-6 * e.electromagnetic);
  // Electrical side: energy in = copper loss + magnetic energy + what became torque. This
  // holds only if the back EMF and the torque constant agree (3/2 e_q i_q = T w).
  const double electrical = e.copper_loss + m.magnetic_energy_j() + e.electromagnetic;
  EXPECT_NEAR(electrical, e.electrical_in, 0.01 * e.electrical_in);
  // And against the closed form of the work: the kinetic energy at the closed-form speed.
  EXPECT_GT(e.electromagnetic, 0.0);
}

TEST(MotorEnergy, AConstantTorqueBalancesExactlyAgainstTheClosedForm) {
  // T theta = 1/2 J w^2 + B int w^2 + Tc theta, with everything in closed form.
  MotorParams p = servo();
  p.load_nm = -0.3;
  p.viscous_nm_per_rad_s = 0;
  Motor m(p);
  m.step(0.01);
  const double a = (0.3 - 0.02) / p.inertia_kgm2;  // constant acceleration
  const double t = 0.01;
  EXPECT_NEAR(m.state().speed_rad_s, a * t, 1e-9 * a * t);
  const double theta = 0.5 * a * t * t;
  EXPECT_NEAR(m.state().angle_turns * 2 * std::numbers::pi, theta, 1e-9 * theta);
  EXPECT_NEAR(-m.state().energy.load_work, m.kinetic_energy_j() + 0.02 * theta, 1e-9);
}

TEST(MotorElectrical, BackEmfLimitsTheCurrentAtSpeed) {
  MotorParams p = servo();
  p.viscous_nm_per_rad_s = 1e-5;
  // A heavier rotor: the EMF rises slowly enough for the PI loop to follow the ramp (a PI
  // lags a ramping disturbance by rate / Ki).
  p.inertia_kgm2 = 1.2e-4;
  Motor m(p);
  const double bus = 24.0;
  m.command(follow(3.0, bus));
  m.step(0.5);
  const double vmax = bus / std::sqrt(3.0);
  const double emf_speed = vmax / (2.0 / 3.0 * p.torque_constant_nm_per_a);  // e_q = vmax
  EXPECT_TRUE(m.state().voltage_limited);
  EXPECT_LT(m.state().current_a.q, 0.2 * 3.0);  // the current cannot follow the command
  EXPECT_LT(m.state().speed_rad_s, emf_speed);
  EXPECT_GT(m.state().speed_rad_s, 0.8 * emf_speed);
  // On a 320 V bus the same motor holds its 3 A well past that speed.
  Motor strong(p);
  strong.command(follow(3.0, 320));
  strong.step(0.03);
  EXPECT_GT(strong.state().speed_rad_s, 1.2 * emf_speed);
  EXPECT_GT(strong.state().current_a.q, 2.5);
}

TEST(MotorElectrical, PhaseCurrentsAreTheVectorOnThreeAxes) {
  Motor m(servo());
  m.command(follow(2.0));
  m.step(0.0137);
  const auto& s = m.state();
  EXPECT_NEAR(s.phase_a[0] + s.phase_a[1] + s.phase_a[2], 0.0, 1e-9);
  const double peak = std::hypot(s.current_a.d, s.current_a.q);
  for (const double i : s.phase_a) EXPECT_LE(std::abs(i), peak + 1e-9);
  const double sum_squares =
      s.phase_a[0] * s.phase_a[0] + s.phase_a[1] * s.phase_a[1] + s.phase_a[2] * s.phase_a[2];
  EXPECT_NEAR(sum_squares, 1.5 * peak * peak, 1e-9);
}

TEST(MotorProtection, APhaseOverTheTripSwitchesTheOutputOff) {
  MotorParams p = servo();
  p.brake_torque_nm = 5;  // held: the whole command flows
  p.brake_engaged = true;
  Motor m(p);
  DriveCommand d = follow(6.0);
  d.phase_trip_a = 5.0;
  m.command(d);
  m.step(0.01);
  EXPECT_NE(m.take_overcurrent(), 0u);
  EXPECT_EQ(m.take_overcurrent(), 0u);  // taken once
  EXPECT_FALSE(m.drive().output_on);
  EXPECT_EQ(m.state().current_a.q, 0.0);
}

TEST(MotorProtection, BeyondMaxSpeedIsARunaway) {
  MotorParams p = servo();
  p.max_speed_rad_s = 100;
  Motor m(p);
  m.command(follow(2.0));
  m.step(0.005);
  EXPECT_FALSE(m.take_runaway());
  m.step(0.1);
  EXPECT_TRUE(m.take_runaway());
}

TEST(MotorTime, StepsCarryPartialPeriods) {
  Motor a(servo()), b(servo());
  a.command(follow(2.0));
  b.command(follow(2.0));
  a.step(0.01);
  for (int k = 0; k < 100; ++k) b.step(0.0001);  // 1.2 periods each
  EXPECT_NEAR(a.state().time_s, b.state().time_s, 1e-12);
  EXPECT_DOUBLE_EQ(a.state().speed_rad_s, b.state().speed_rad_s);
}

TEST(MotorParamsCheck, NonPhysicalValuesAreRefused) {
  MotorParams p = servo();
  p.inertia_kgm2 = -1;
  EXPECT_THROW(Motor{p}, MotorError);
  p = servo();
  p.cogging_nm = 0.1;  // without a period
  EXPECT_THROW(Motor{p}, MotorError);
}
