// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual 8I20 driving a motor: QSETPOINT and ANGLE through the card's lead and current
// loop, the rules that switch the bridge off, and the faults a motor can cause.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>

#include "../sim/bench.hpp"
#include "motor/motor.hpp"
#include "sim/bits.hpp"
#include "sim/control.hpp"
#include "sim/error.hpp"

namespace i20::sim::test {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

motor::MotorParams servo() {
  motor::MotorParams p;
  p.pole_pairs = 4;
  p.winding = {0.6, 1.75e-3};
  p.torque_constant_nm_per_a = 0.2;
  p.inertia_kgm2 = 1.2e-5;
  p.viscous_nm_per_rad_s = 1e-3;
  p.coulomb_nm = 0.01;
  return p;
}

// An 8I20 in operate mode (MAXCURRENT 10 A, KQP/KQI 50/150000, 320 V) with the servo on it.
DeviceOptions with_motor(const motor::MotorParams& params = servo()) {
  DeviceOptions o;
  o.mode = FramingMode::Operate;
  o.motor = params;
  return o;
}

class CardWithMotor : public ::testing::Test {
 protected:
  // One host write of ANGLE (low word) and QSETPOINT (high word), as SSLBP's cycle does.
  void command(std::uint16_t angle, std::int16_t setpoint) {
    const auto address = b().address_of("ANGLE");
    ASSERT_EQ(b().address_of("QSETPOINT"), address + 2);
    const auto q = static_cast<std::uint16_t>(setpoint);
    b().raw(framed_write32(address, static_cast<std::uint32_t>(q) << 16 | angle));
  }
  static lbp::Bytes framed_write32(std::uint16_t address, std::uint32_t value) {
    lbp::Bytes cmd{0x66, static_cast<lbp::Byte>(address), static_cast<lbp::Byte>(address >> 8)};
    for (int k = 0; k < 4; ++k) cmd.push_back(static_cast<lbp::Byte>(value >> (8 * k)));
    cmd.push_back(lbp::crc8(cmd));
    return cmd;
  }
  const motor::MotorState& state() const { return b().card.motor()->state(); }
  // The rotor's electrical angle as ANGLE counts (bldc's rotor-angle: no lead added).
  std::uint16_t rotor_angle() const {
    return static_cast<std::uint16_t>(std::lround(state().electrical_angle_rad / kTwoPi * 65536.0) & 0xFFFF);
  }
  // A 1 kHz servo thread: ANGLE from the rotor, a fixed QSETPOINT.
  void servo_for(Clock::duration d, std::int16_t setpoint) {
    for (auto end = b().t + d; b().t < end;) {
      command(rotor_angle(), setpoint);
      b().wait(std::chrono::milliseconds(1));
    }
  }
  std::uint16_t fault() const { return b().card.amplifier().fault(); }

  Bench& b() { return *bench_; }
  const Bench& b() const { return *bench_; }
  std::optional<Bench> bench_{std::in_place, with_motor()};
};

TEST_F(CardWithMotor, PositiveQsetpointTurnsTheRotorForwardWhenAngleFollowsIt) {
  servo_for(std::chrono::milliseconds(30), 6553);  // 2 A of MAXCURRENT 10 A
  EXPECT_EQ(fault(), 0u);
  EXPECT_GT(state().speed_rad_s, 50.0);
  EXPECT_GT(state().angle_turns, 0.1);
}

TEST_F(CardWithMotor, NegativeQsetpointTurnsItBackward) {
  servo_for(std::chrono::milliseconds(30), -6553);
  EXPECT_EQ(fault(), 0u);
  EXPECT_LT(state().speed_rad_s, -50.0);
  EXPECT_LT(state().angle_turns, -0.1);
}

TEST_F(CardWithMotor, TheCurrentIsQsetpointTimesMaxcurrentOnTheQAxis) {
  // A rotor held by its brake: the whole current goes into torque, 90 degrees ahead of ANGLE.
  auto p = servo();
  p.brake_torque_nm = 5;
  p.brake_engaged = true;
  Bench held{with_motor(p)};
  for (int k = 0; k < 20; ++k) {
    const auto wire = framed_write32(held.address_of("ANGLE"), static_cast<std::uint32_t>(9830) << 16);
    held.raw(wire);
    held.wait(std::chrono::milliseconds(1));
  }
  const auto& s = held.card.motor()->state();
  EXPECT_NEAR(s.current_a.q, 9830 / 32767.0 * 10.0, 0.03);  // 3 A
  EXPECT_NEAR(s.current_a.d, 0.0, 0.03);
  EXPECT_NEAR(s.torque_nm, 0.2 * 3.0, 0.01);
  EXPECT_EQ(s.speed_rad_s, 0.0);
}

TEST_F(CardWithMotor, AFixedAngleMakesTheRotorAlignAndStop) {
  for (int k = 0; k < 50; ++k) {  // ANGLE stays 0: a missing commutation
    command(0, 6553);
    b().wait(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(fault(), 0u);
  // The current sits 90 electrical degrees ahead of ANGLE; the magnet lines up with it.
  EXPECT_NEAR(state().electrical_angle_rad, std::numbers::pi / 2, 0.05);
  EXPECT_NEAR(state().speed_rad_s, 0.0, 0.5);
}

TEST_F(CardWithMotor, TheWatchdogSwitchesTheBridgeOff) {
  servo_for(std::chrono::milliseconds(20), 6553);
  // (ANGLE changes once a millisecond, so the vector lags the rotor's q axis in between.)
  ASSERT_GT(std::hypot(state().current_a.d, state().current_a.q), 1.5);
  b().wait(std::chrono::milliseconds(39));
  EXPECT_TRUE(b().card.motor()->drive().output_on) << "fed within 40 ms";
  b().wait(std::chrono::milliseconds(20));
  EXPECT_EQ(fault() & fault::kWatchdog, fault::kWatchdog);
  EXPECT_FALSE(b().card.motor()->drive().output_on);
  EXPECT_EQ(std::hypot(state().current_a.d, state().current_a.q), 0.0);
  EXPECT_EQ(state().torque_nm, 0.0);
  const double work = state().energy.electromagnetic;
  b().wait(std::chrono::milliseconds(5));
  EXPECT_EQ(state().energy.electromagnetic, work) << "no torque, no work";
}

TEST_F(CardWithMotor, AFaultStopsTheTorque) {
  servo_for(std::chrono::milliseconds(10), 6553);
  b().card.world().settings().enable = false;
  servo_for(std::chrono::milliseconds(3), 6553);
  EXPECT_EQ(fault() & fault::kNoEnable, fault::kNoEnable);
  EXPECT_EQ(state().current_a.q, 0.0);
  EXPECT_FALSE(b().card.motor()->drive().output_on);
}

TEST_F(CardWithMotor, SetupModeDrivesNothing) {
  DeviceOptions o = with_motor();
  o.mode = FramingMode::Setup;
  Bench setup{o};
  setup.write16(setup.address_of("QSETPOINT"), 16000);
  setup.wait(std::chrono::milliseconds(20));
  EXPECT_EQ(setup.card.motor()->state().current_a.q, 0.0);
  EXPECT_EQ(setup.card.motor()->state().angle_turns, 0.0);
}

TEST_F(CardWithMotor, AnOscillatingLoopLatchesAPhaseCurrentFault) {
  // KQP far too high for this winding: the loop rings until a phase passes 125% of
  // MAXCURRENT; the card latches that phase's fault and switches off.
  b().card.amplifier().poke("KQP", 2000);
  b().card.amplifier().poke("KDP", 2000);
  servo_for(std::chrono::milliseconds(10), 16000);
  const std::uint16_t phases = fault::kULoop | fault::kVLoop | fault::kWLoop;
  EXPECT_NE(fault() & phases, 0u);
  EXPECT_EQ(fault() & ~phases, 0u);
  EXPECT_FALSE(b().card.motor()->drive().output_on);
  // Until CLEARFAULT the loop stays off.
  servo_for(std::chrono::milliseconds(5), 16000);
  EXPECT_EQ(state().current_a.q, 0.0);
}

TEST_F(CardWithMotor, TheSameGainsInRangeDoNotTrip) {
  servo_for(std::chrono::milliseconds(10), 16000);
  EXPECT_EQ(fault(), 0u);
}

TEST_F(CardWithMotor, ARunawayBeyondMaxSpeedLatchesBusOverVoltage) {
  auto p = servo();
  p.max_speed_rad_s = 100;
  bench_.emplace(with_motor(p));
  servo_for(std::chrono::milliseconds(40), 6553);
  EXPECT_EQ(fault() & fault::kBusHigh, fault::kBusHigh);
  EXPECT_FALSE(b().card.motor()->drive().output_on);
}

TEST_F(CardWithMotor, WithoutAMotorThereIsNoMotorState) {
  Bench plain;
  EXPECT_EQ(plain.card.motor(), nullptr);
  EXPECT_THROW(apply_control(plain.card, "motor load 0.1Nm", plain.t), ControlError);
  EXPECT_EQ(describe_state(plain.card).find("motor"), std::string::npos);
}

TEST_F(CardWithMotor, ControlLinesStepTheLoadLive) {
  EXPECT_EQ(apply_control(b().card, "motor load -0.2Nm", b().t), "ok");  // drives it forward
  EXPECT_DOUBLE_EQ(b().card.motor()->params().load_nm, -0.2);
  b().card.world().settings().enable = false;  // no torque from the card
  b().wait(std::chrono::milliseconds(20));
  EXPECT_GT(state().speed_rad_s, 10.0);
  EXPECT_THROW(apply_control(b().card, "motor load 3", b().t), ControlError);
  EXPECT_THROW(apply_control(b().card, "motor colour red", b().t), ControlError);
  EXPECT_DOUBLE_EQ(b().card.motor()->params().load_nm, -0.2) << "a refused line changes nothing";
  EXPECT_EQ(apply_control(b().card, "motor brake.engaged true", b().t), "ok");
  EXPECT_TRUE(b().card.motor()->params().brake_engaged);
}

TEST_F(CardWithMotor, InjectedSensorFaultsFreezeTheReadings) {
  auto p = servo();
  p.encoder = motor::EncoderDescription{4000, 1, 0};
  p.halls = motor::HallDescription{};
  p.load_nm = -0.2;
  bench_.emplace(with_motor(p));
  b().wait(std::chrono::milliseconds(5));
  EXPECT_EQ(apply_control(b().card, "motor fault encoder-lost on", b().t), "ok");
  EXPECT_EQ(apply_control(b().card, "motor fault hall-stuck on", b().t), "ok");
  const auto frozen = b().card.motor()->read_sensors();
  b().wait(std::chrono::milliseconds(20));
  const auto later = b().card.motor()->read_sensors();
  EXPECT_EQ(later.encoder_count, frozen.encoder_count);
  EXPECT_EQ(later.hall_code, frozen.hall_code);
  apply_control(b().card, "motor fault encoder-lost off", b().t);
  EXPECT_GT(*b().card.motor()->read_sensors().encoder_count, *frozen.encoder_count);
  const std::string shown = apply_control(b().card, "show", b().t);
  for (const char* field :
       {"motor_angle=", "speed=", "electrical=", "encoder=", "halls=", "(stuck)", "iu=", "iv=", "iw="})
    EXPECT_NE(shown.find(field), std::string::npos) << field << " in " << shown;
}

}  // namespace
}  // namespace i20::sim::test
