// SPDX-License-Identifier: GPL-2.0-or-later
// The machine behind the motor (motor files' `machine:`): a load reflected through a lead, a
// rigid or a compliant coupling to it, its resonance and its energy balance, against closed
// forms. This is the truth a tuning tool is judged by, so it is checked against physics.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "motor/error.hpp"
#include "motor/loader.hpp"
#include "motor/motor.hpp"

using namespace i20::motor;

namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

MotorParams servo() {
  MotorParams p;
  p.pole_pairs = 4;
  p.winding = {0.6, 1.75e-3};
  p.torque_constant_nm_per_a = 0.2;
  p.inertia_kgm2 = 1.2e-5;
  return p;
}

// A 40 kg table on a 5 mm screw: 40 (0.005 / 2 pi)^2 = 2.533e-5 kg m^2 at the motor.
MotorParams on_a_screw(double stiffness = 0, double damping = 0) {
  MotorParams p = servo();
  p.machine.lead_m_per_turn = 0.005;
  p.machine.mass_kg = 40;
  p.machine.stiffness_nm_per_rad = stiffness;
  p.machine.damping_nm_per_rad_s = damping;
  return p;
}

DriveCommand follow(double iq) {
  const double wc = 2 * std::numbers::pi * 500;
  DriveCommand d;
  d.output_on = true;
  d.frame_follows_rotor = true;
  d.current_a = {0, iq};
  d.d_gains = d.q_gains = {1.75e-3 * wc, 0.6 * wc};
  d.bus_voltage_v = 320;
  return d;
}

double twist_rad(const Motor& m) {
  return (m.state().angle_turns - m.state().load_angle_turns) * kTwoPi;
}

}  // namespace

TEST(MotorMachine, AMassOnAScrewReachesTheShaftAsMTimesLeadOverTwoPiSquared) {
  const MotorParams p = on_a_screw();
  const double reflected = 40 * std::pow(0.005 / kTwoPi, 2);
  EXPECT_NEAR(reflected_load_inertia(p), reflected, 1e-15);
  EXPECT_NEAR(total_inertia(p), 1.2e-5 + reflected, 1e-15);
  EXPECT_FALSE(compliant(p));
  EXPECT_FALSE(resonance_hz(p));
}

TEST(MotorMachine, ARigidLoadAcceleratesWithTheRotorAndMovesTheTableByTheLead) {
  MotorParams p = on_a_screw();
  p.load_nm = -0.3;  // drives forward
  Motor m(p);
  m.step(0.01);
  const double a = 0.3 / total_inertia(p), t = 0.01;
  EXPECT_NEAR(m.state().speed_rad_s, a * t, 1e-9 * a * t);
  EXPECT_EQ(m.state().load_angle_turns, m.state().angle_turns);
  const double turns = 0.5 * a * t * t / kTwoPi;
  EXPECT_NEAR(m.state().machine_position_m, turns * 0.005, 1e-9 * turns * 0.005);
  EXPECT_NEAR(-m.state().energy.load_work, m.kinetic_energy_j(), 1e-9 * m.kinetic_energy_j());
}

TEST(MotorMachine, ACompliantCouplingRingsAtItsResonance) {
  // Frictionless; a load torque pushes the table back and the two masses ring about the
  // twist that accelerates the rotor with it: k x = J_motor F / (J_motor + J_load).
  const double k = 50;
  MotorParams p = on_a_screw(k);
  p.load_nm = 0.1;
  const double expected_hz = std::sqrt(k * (1 / p.inertia_kgm2 + 1 / reflected_load_inertia(p))) / kTwoPi;
  ASSERT_NEAR(*resonance_hz(p), expected_hz, 1e-9);
  ASSERT_GT(expected_hz, 250);
  ASSERT_LT(expected_hz, 400);
  Motor m(p);
  const double centre = p.inertia_kgm2 * 0.1 / total_inertia(p) / k;
  std::vector<double> crossings;
  double before = twist_rad(m) - centre;
  for (int k = 0; k < 1200; ++k) {  // 0.1 s in PWM periods
    const double t0 = m.state().time_s;
    m.step(m.period_s());
    const double now = twist_rad(m) - centre;
    if ((before < 0) != (now < 0)) crossings.push_back(t0 + m.period_s() * before / (before - now));
    before = now;
  }
  ASSERT_GT(crossings.size(), 40u);
  const double period =
      2 * (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(1 / period, expected_hz, 0.005 * expected_hz);
  // Undamped: it still rings as wide as it started (the step neither gains nor loses energy).
  double widest = 0;
  for (int k = 0; k < 48; ++k) {
    m.step(m.period_s());
    widest = std::max(widest, std::abs(twist_rad(m) - centre));
  }
  EXPECT_NEAR(widest, std::abs(centre), 0.02 * std::abs(centre));
}

TEST(MotorMachine, EnergyBalancesAcrossADampedCouplingUnderTheCurrentLoop) {
  MotorParams p = on_a_screw(60, 0.004);
  p.viscous_nm_per_rad_s = 1e-4;
  p.coulomb_nm = 0.01;
  p.cogging_nm = 0.005;
  p.cogging_periods_per_turn = 24;
  p.load_nm = 0.05;
  Motor m(p);
  m.command(follow(2.0));
  m.step(0.04);
  const auto& e = m.state().energy;
  ASSERT_GT(e.coupling_loss, 0.0);
  ASSERT_GT(m.spring_energy_j(), 0.0);
  ASSERT_GT(m.state().load_speed_rad_s, 10.0);
  const double mechanical = m.kinetic_energy_j() + m.spring_energy_j() + e.friction_loss + e.viscous_loss +
                            e.load_work + e.cogging_work + e.coupling_loss;
  EXPECT_NEAR(mechanical, e.electromagnetic, 0.002 * e.electromagnetic);
  const double electrical = e.copper_loss + m.magnetic_energy_j() + e.electromagnetic;
  EXPECT_NEAR(electrical, e.electrical_in, 0.01 * e.electrical_in);
}

TEST(MotorMachine, AHangingLoadTwistsTheCouplingByItsWeightOverTheStiffness) {
  // A vertical axis held by the brake: the table sags until the spring carries its weight.
  MotorParams p = on_a_screw(60, 0.02);
  p.load_nm = 0.2;
  p.brake_torque_nm = 1.0;
  p.brake_engaged = true;
  Motor m(p);
  m.step(0.3);
  EXPECT_TRUE(m.state().stuck);
  EXPECT_EQ(m.state().angle_turns, 0.0);
  EXPECT_NEAR(twist_rad(m), 0.2 / 60, 0.01 * 0.2 / 60);
  EXPECT_NEAR(m.state().load_speed_rad_s, 0.0, 1e-3);
}

TEST(MotorMachine, ACouplingMadeRigidLiveKeepsTheMomentum) {
  MotorParams p = on_a_screw(60);
  Motor m(p);
  m.command(follow(2.0));
  m.step(0.01);
  m.command({});
  const double momentum =
      p.inertia_kgm2 * m.state().speed_rad_s + reflected_load_inertia(p) * m.state().load_speed_rad_s;
  p.machine.stiffness_nm_per_rad = 0;
  m.set_params(p);
  m.step(m.period_s());
  EXPECT_NEAR(total_inertia(p) * m.state().speed_rad_s, momentum, 1e-9);
  EXPECT_EQ(m.state().load_speed_rad_s, m.state().speed_rad_s);
}

TEST(MotorMachine, WhatCannotBeAMachineIsRefusedWithItsKey) {
  const auto refused = [](MotorParams p, const char* key) {
    try {
      validate(p);
    } catch (const MotorError& e) {
      return std::string(e.what()).find(key) != std::string::npos;
    }
    return false;
  };
  MotorParams p = servo();
  p.machine.mass_kg = 10;  // no lead to reflect it through
  EXPECT_TRUE(refused(p, "machine.mass needs machine.lead"));
  p = servo();
  p.machine.stiffness_nm_per_rad = 100;  // nothing hangs on it
  EXPECT_TRUE(refused(p, "machine.stiffness couples a load"));
  p = on_a_screw();
  p.machine.damping_nm_per_rad_s = 0.01;
  EXPECT_TRUE(refused(p, "machine.damping belongs to a compliant coupling"));
  p = on_a_screw(1e9);
  EXPECT_TRUE(refused(p, "Hz, above the model's 5000 Hz"));
  p = on_a_screw();
  p.machine.load_inertia_kgm2 = -1e-5;
  EXPECT_TRUE(refused(p, "machine.load_inertia must not be negative"));
}

TEST(MotorMachine, AMotorFileDescribesItsMachineWithUnits) {
  const MotorParams p = parse_motor(R"(pole_pairs: 4
resistance: 0.6ohm
inductance: 1.75mH
torque_constant: 0.2Nm/A
inertia: 0.12kgcm^2
load: 0.39Nm
machine:
  lead: 5mm
  mass: 40kg
  load_inertia: 0.5kgcm^2
  stiffness: 60Nm/rad
  damping: 0.004Nm/(rad/s)
)",
                                    "axis.yaml");
  EXPECT_DOUBLE_EQ(p.machine.lead_m_per_turn, 0.005);
  EXPECT_DOUBLE_EQ(p.machine.mass_kg, 40);
  EXPECT_DOUBLE_EQ(p.machine.load_inertia_kgm2, 0.5e-4);
  EXPECT_DOUBLE_EQ(p.machine.stiffness_nm_per_rad, 60);
  EXPECT_DOUBLE_EQ(p.machine.damping_nm_per_rad_s, 0.004);
  EXPECT_TRUE(compliant(p));
  const auto message = [](const char* text) {
    try {
      parse_motor(text, "axis.yaml");
    } catch (const MotorError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const char* head =
      "pole_pairs: 4\nresistance: 0.6ohm\ninductance: 1.75mH\ntorque_constant: 0.2Nm/A\n"
      "inertia: 0.12kgcm^2\n";
  EXPECT_EQ(message((std::string(head) + "machine: {lead: 5}\n").c_str()),
            "axis.yaml:6: machine.lead: 5: a length needs its unit (5mm, 5um, 5m, 5in)");
  EXPECT_EQ(message((std::string(head) + "machine: {lead: 5mm, stiffness: 60Nm}\n").c_str()),
            "axis.yaml:6: machine.stiffness: 60Nm: a stiffness is in Nm/rad, kNm/rad or Nm/deg, not Nm");
  EXPECT_EQ(
      message((std::string(head) + "machine: {mass: 40kg}\n").c_str()),
      "axis.yaml: machine.mass needs machine.lead (the travel per motor turn) to reach the motor shaft");
}
