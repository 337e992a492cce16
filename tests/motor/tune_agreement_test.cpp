// SPDX-License-Identifier: GPL-2.0-or-later
// One plant: `i20 tune`'s simulated step (lib/profile) and the virtual 8I20's motor run the
// same loop on the same winding, so for a held rotor they draw the same current, period by
// period, from the same card gains.
#include <gtest/gtest.h>

#include <chrono>

#include "../sim/bench.hpp"
#include "motor/motor.hpp"
#include "profile/step_response.hpp"

namespace {

using namespace i20;

motor::MotorParams held_servo() {
  motor::MotorParams p;
  p.pole_pairs = 4;
  p.winding = {0.6, 1.75e-3};
  p.torque_constant_nm_per_a = 0.2;
  p.inertia_kgm2 = 1.2e-5;
  p.brake_torque_nm = 10;  // held: a locked rotor, as tune's model assumes
  p.brake_engaged = true;
  return p;
}

TEST(OnePlant, TheMotorDrawsTunesStepPeriodByPeriod) {
  const double max_current = 10, bus = 320;
  for (const auto& [kp, ki] :
       {std::pair<std::int64_t, std::int64_t>{50, 150000}, {20, 60000}, {120, 400000}}) {
    profile::StepRequest request;
    request.motor = {0.6, 1.75e-3};
    request.max_current_a = max_current;
    request.bus_voltage_v = bus;
    request.kp = kp;
    request.ki = ki;
    request.duration_s = 0.005;
    const auto predicted = profile::simulate_step(request);

    motor::Motor m(held_servo());
    motor::DriveCommand d;
    d.output_on = true;
    d.frame_angle_rad = 0;  // ANGLE 0 on a rotor at electrical 0: the card's q axis is the rotor's
    d.current_a = {0, predicted.step_a};
    d.q_gains = d.d_gains = motor::physical_gains(kp, ki, max_current, bus);
    d.bus_voltage_v = bus;
    m.command(d);
    for (std::size_t k = 0; k < predicted.samples.size(); ++k) {
      ASSERT_NEAR(m.state().current_a.q, predicted.samples[k].current_a, 1e-9 * predicted.step_a)
          << "KQP " << kp << " KQI " << ki << " period " << k;
      m.step(m.period_s());
    }
    EXPECT_EQ(m.state().speed_rad_s, 0.0);
  }
}

TEST(OnePlant, TheVirtualCardUsesTunesGainsForItsWorkingValues) {
  sim::DeviceOptions o;
  o.mode = sim::FramingMode::Operate;
  o.motor = held_servo();
  sim::test::Bench b{o};
  b.card.amplifier().poke("KQP", 77);
  b.card.amplifier().poke("KQI", 123456);
  b.card.amplifier().poke("MAXCURRENT", 1500);
  b.wait(std::chrono::milliseconds(1));
  profile::StepRequest request;
  request.motor = {0.6, 1.75e-3};
  request.max_current_a = 15;
  request.bus_voltage_v = 320;  // the simulator's default bus
  request.kp = 77;
  request.ki = 123456;
  const auto predicted = profile::simulate_step(request);
  const auto& drive = b.card.motor()->drive();
  EXPECT_DOUBLE_EQ(drive.q_gains.kp_v_per_a, predicted.gains.kp_v_per_a);
  EXPECT_DOUBLE_EQ(drive.q_gains.ki_v_per_as, predicted.gains.ki_v_per_as);
  EXPECT_DOUBLE_EQ(drive.bus_voltage_v, 320);
  EXPECT_DOUBLE_EQ(drive.phase_trip_a, 1.25 * 15);
}

}  // namespace
