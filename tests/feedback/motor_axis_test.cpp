// SPDX-License-Identifier: GPL-2.0-or-later
// A motor on a virtual 8I20 behind the virtual card's axis: a host commutates it through
// SSLBP normal mode (ANGLE = the rotor's electrical angle, the 8I20 adds its own lead) and
// reads the axis's encoder and Hall inputs through LBP16, as LinuxCNC's hostmot2 + bldc do.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <span>

#include "error/error.hpp"
#include "ethsim/motor_feedback.hpp"
#include "ethsim/server.hpp"
#include "ethsim/simulated_host.hpp"
#include "ethsim/virtual_8i20_remote.hpp"
#include "ethsim/virtual_board.hpp"
#include "hostmot2/hostmot2.hpp"
#include "lbp16/lbp16.hpp"
#include "motor/loader.hpp"
#include "motor/sensors.hpp"
#include "sim/control.hpp"

using namespace i20;
using namespace i20::ethsim;
using namespace std::chrono_literals;
namespace hm2 = i20::lbp::hm2;
namespace lbp16 = i20::lbp::lbp16;

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// A 4-pole-pair servo with a 2000-count encoder and bldc-pattern-25 Halls, on channel 0.
std::string servo_yaml(const std::string& encoder_direction = "1",
                       const std::string& hall_inputs = "[0, 1, 2]") {
  return "name: test servo\npole_pairs: 4\nresistance: 0.6ohm\ninductance: 1.75mH\n"
         "torque_constant: 0.2Nm/A\ninertia: 0.12kgcm^2\nfriction:\n  viscous: 0.02mNm/(rad/s)\n"
         "  coulomb: 0.01Nm\nchannel: 0\nencoder:\n  counts_per_turn: 2000\n  direction: " +
         encoder_direction + "\n  index_angle: 0deg\nhalls:\n  pattern: 25\n  inputs: " + hall_inputs + "\n";
}

// The 7I92T servo card with an 8I20 driving `params` on port 0 channel 0, its axis wired.
class Axis {
 public:
  explicit Axis(motor::MotorParams params) : card_(options(std::move(params), t0_), t0_) {
    auto* remote = dynamic_cast<Virtual8i20Remote*>(card_.sslbp(0).remote(0));
    amplifier_ = &remote->device();
    axis_ = connect_motor_feedback(card_, *amplifier_, 0, 0);
    const auto ident = hm2::IdentArea::parse(read_bytes(hm2::kCookieAddress, 4));
    const auto idrom_address = static_cast<std::uint16_t>(ident.idrom_address);
    idrom_ = hm2::Idrom::parse(read_bytes(idrom_address, 16));
    modules_ = hm2::parse_modules(read_bytes(
        static_cast<std::uint16_t>(idrom_address + idrom_.offset_to_modules), hm2::kMaxModules * 3));
  }

  std::optional<unsigned> axis() const { return axis_; }
  const motor::Motor& motor() const { return *amplifier_->motor(); }
  sim::Virtual8i20& amplifier() { return *amplifier_; }
  Clock::time_point now() const { return now_; }

  // The 1 kHz servo thread commutates with ANGLE = the rotor's electrical angle and a
  // fixed QSETPOINT, for `d`; every period it reads the encoder count and the Hall pins.
  struct Sample {
    std::int64_t count;  // unwrapped from the 16-bit register
    double motor_turns;
    // The card reads the shaft at its own time; the motor's state holds at its last PWM
    // period (1/12 ms), and the 8I20 runs ahead of the card by the serial exchange's time.
    // Two PWM periods of travel and the count's own quantum cover both.
    double tolerance_counts;
    unsigned hall_inputs;  // card inputs 0, 1, 2 as bits 2, 1, 0
    unsigned motor_hall_code;
  };
  std::vector<Sample> servo(Clock::duration d, std::int16_t qsetpoint) {
    HostOptions o;
    o.mask = 0x01;
    o.interface0 = [this, qsetpoint](unsigned) {
      const double electrical = motor().state().electrical_angle_rad / kTwoPi;
      const auto angle = static_cast<std::uint32_t>(std::lround(electrical * 65536.0)) & 0xFFFFu;
      return static_cast<std::uint32_t>(static_cast<std::uint16_t>(qsetpoint)) << 16 | angle;
    };
    // A new command: a new host (same port), which restarts normal mode first.
    host_.emplace(o);
    std::vector<Sample> samples;
    for (const auto end = now_ + d; now_ < end;) {
      now_ += 1ms;
      host_->run_until(card_, now_);
      samples.push_back(read_feedback());
    }
    return samples;
  }

 private:
  static VirtualBoardOptions options(motor::MotorParams params, Clock::time_point t0) {
    VirtualBoardOptions o;
    o.config = BoardConfig::preset_7i92t_servo();
    o.remotes = [params, t0](unsigned port, unsigned channel) -> std::unique_ptr<RemoteLbpDevice> {
      if (port != 0 || channel != 0) return nullptr;
      sim::DeviceOptions device = Virtual8i20Remote::default_options();
      device.motor = params;
      return std::make_unique<Virtual8i20Remote>(device, t0);
    };
    return o;
  }

  Sample read_feedback() {
    const std::vector<lbp16::Command> commands{
        lbp16::read_hm2(address(hm2::gtag::kEncoder, hm2::encoder_reg::kCount, 0)),
        lbp16::read_hm2(address(hm2::gtag::kIoPort, hm2::ioport_reg::kData, 0))};
    const auto parts =
        lbp16::split_reply(commands, card_.handle(lbp16::encode_packet(commands), now_).value());
    const auto raw = static_cast<std::uint16_t>(lbp::read_le(parts[0]));
    count_ += static_cast<std::int16_t>(static_cast<std::uint16_t>(raw - last_raw_));
    last_raw_ = raw;
    const auto gpio = static_cast<std::uint32_t>(lbp::read_le(parts[1]));
    const unsigned first = card_.config().axes.at(0).hall_pins[0];
    const unsigned inputs =
        (gpio >> first & 1u) << 2 | (gpio >> (first + 1) & 1u) << 1 | (gpio >> (first + 2) & 1u);
    return Sample{
        .count = count_,
        .motor_turns = motor().state().angle_turns,
        .tolerance_counts = 2.0 + std::abs(motor().state().speed_rad_s) / kTwoPi * 2000.0 * 2.0 / 12000.0,
        .hall_inputs = inputs,
        .motor_hall_code = motor().read_sensors().hall_code.value()};
  }

  std::uint16_t address(std::uint8_t gtag, unsigned reg, unsigned instance) const {
    for (const auto& m : modules_)
      if (m.gtag == gtag) return m.register_address(idrom_, reg, instance);
    throw std::runtime_error("no module with that GTag");
  }
  lbp::Bytes read_bytes(std::uint16_t address, unsigned words) {
    const std::vector<lbp16::Command> commands{lbp16::read_hm2(address, words)};
    return lbp16::split_reply(commands, card_.handle(lbp16::encode_packet(commands), now_).value())[0];
  }

  Clock::time_point t0_ = Clock::time_point{} + 1h;
  Clock::time_point now_ = t0_;
  VirtualBoard card_;
  sim::Virtual8i20* amplifier_ = nullptr;
  std::optional<unsigned> axis_;
  std::optional<SimulatedHost> host_;
  hm2::Idrom idrom_{};
  std::vector<hm2::ModuleDescriptor> modules_;
  std::int64_t count_ = 0;
  std::uint16_t last_raw_ = 0;
};

motor::MotorParams servo(const std::string& direction = "1", const std::string& inputs = "[0, 1, 2]") {
  return motor::parse_motor(servo_yaml(direction, inputs), "test servo");
}

// The samples once normal mode runs: a new host's first periods stop and restart the
// port, and those serial exchanges run the 8I20 (and its motor) ahead of the card's time
// by up to their timeouts, so there the motor's state is not what the card sampled.
std::span<const Axis::Sample> running(const std::vector<Axis::Sample>& samples) {
  return std::span(samples).subspan(3);
}

// 2 A of the default MAXCURRENT (10 A): QSETPOINT 32767 = +MAXCURRENT (8I20 manual).
constexpr std::int16_t kTwoAmps = 6553;

}  // namespace

TEST(MotorAxis, TheEncoderCountFollowsTheCommutatedMotorForwardAndBack) {
  Axis axis(servo());
  ASSERT_EQ(axis.axis(), 0u);
  const auto forward = axis.servo(100ms, kTwoAmps);
  EXPECT_EQ(axis.amplifier().amplifier().fault(), 0u);
  ASSERT_GT(forward.back().motor_turns, 0.5) << "2 A turns the rotor forward";
  for (const auto& s : running(forward))
    EXPECT_NEAR(static_cast<double>(s.count), s.motor_turns * 2000.0, s.tolerance_counts)
        << "the card reads the motor's shaft";
  const auto back = axis.servo(200ms, -kTwoAmps);
  EXPECT_LT(back.back().motor_turns, forward.back().motor_turns - 0.5) << "-2 A turns it back";
  for (const auto& s : running(back))
    EXPECT_NEAR(static_cast<double>(s.count), s.motor_turns * 2000.0, s.tolerance_counts);
  EXPECT_LT(back.back().count, forward.back().count);
}

TEST(MotorAxis, TheHallInputsReadTheMotorsPattern25Code) {
  Axis axis(servo());
  const auto samples = axis.servo(60ms, kTwoAmps);
  unsigned disagreements = 0, codes_seen = 0;
  for (const auto& s : samples) {
    ASSERT_NE(s.hall_inputs, 0u) << "pattern 25 never reads 000";
    ASSERT_NE(s.hall_inputs, 7u) << "pattern 25 never reads 111";
    if (s.hall_inputs != s.motor_hall_code) ++disagreements;
    codes_seen |= 1u << s.hall_inputs;
  }
  // The card samples the shaft at the card's time, the motor's sensors at its last PWM
  // period: at most a sample on a Hall edge may differ.
  EXPECT_LE(disagreements, 2u);
  EXPECT_EQ(codes_seen, 0b0111'1110u) << "every one of the six codes passed";
}

// The motor's sensor faults reach the card's inputs, as the serial simulator shows them: a
// lost encoder stops counting and stuck Halls hold their code while the shaft turns on.
TEST(MotorAxis, SensorFaultsFreezeTheCardsEncoderAndHallInputs) {
  Axis axis(servo());
  const auto before = axis.servo(30ms, kTwoAmps);
  ASSERT_EQ(sim::apply_control(axis.amplifier(), "motor fault encoder-lost on", axis.now()), "ok");
  ASSERT_EQ(sim::apply_control(axis.amplifier(), "motor fault hall-stuck on", axis.now()), "ok");
  const auto during = axis.servo(100ms, kTwoAmps);
  ASSERT_GT(during.back().motor_turns, during.front().motor_turns + 0.5) << "the shaft turns on";
  for (const auto& s : during) {
    EXPECT_NEAR(static_cast<double>(s.count), static_cast<double>(during.front().count), 1.0)
        << "the lost encoder's count stays";
    EXPECT_EQ(s.hall_inputs, during.front().hall_inputs) << "the stuck Halls' code stays";
  }
  EXPECT_NEAR(static_cast<double>(during.front().count), static_cast<double>(before.back().count),
              before.back().tolerance_counts + 1.0)
      << "frozen where the fault came";
  ASSERT_EQ(sim::apply_control(axis.amplifier(), "motor fault encoder-lost off", axis.now()), "ok");
  const auto after = axis.servo(20ms, kTwoAmps);
  EXPECT_NEAR(static_cast<double>(after.back().count), after.back().motor_turns * 2000.0,
              after.back().tolerance_counts)
      << "the encoder counts the shaft again";
}

TEST(MotorAxis, ANegativeEncoderDirectionCountsDownWhileTheMotorTurnsForward) {
  Axis axis(servo("-1"));
  const auto forward = axis.servo(100ms, kTwoAmps);
  ASSERT_GT(forward.back().motor_turns, 0.5);
  EXPECT_NEAR(static_cast<double>(forward.back().count), -forward.back().motor_turns * 2000.0,
              forward.back().tolerance_counts);
}

TEST(MotorAxis, HallWiringFromTheMotorFileSwapsTheCardInputs) {
  Axis axis(servo("1", "[1, 0, 2]"));  // Hall 1 on input 1, Hall 2 on input 0
  const auto samples = axis.servo(60ms, kTwoAmps);
  unsigned agree = 0;
  for (const auto& s : samples) {
    const unsigned c = s.motor_hall_code;
    const unsigned swapped = (c >> 1 & 1u) << 2 | (c >> 2 & 1u) << 1 | (c & 1u);
    if (s.hall_inputs == swapped) ++agree;
  }
  EXPECT_GE(agree, samples.size() - 2);
}

TEST(MotorAxis, HallInputsMustBeTheAxissThree) {
  EXPECT_THROW(hall_spec(servo("1", "[0, 0, 2]")), UsageError);
}

TEST(MotorAxis, TheServerWiresEachMotorToTheAxisOfItsChannel) {
  ServerOptions o;
  o.listen = eth::HostPort{.ip = "127.0.0.1", .port = 0};
  o.card = BoardKind::I7i92t;
  o.config = BoardConfig::preset_7i92t_servo();
  o.amplifiers = {{0, 0}, {0, 1}};
  auto second = servo();
  second.channel = 1;
  o.motors = {second};
  BoardServer server(o);
  ASSERT_EQ(server.motor_axes().size(), 1u);
  EXPECT_EQ(server.motor_axes()[0].channel, 1u);
  EXPECT_EQ(server.motor_axes()[0].axis, 1u) << "7I92T servo: axis 1 is port 0 channel 1";

  o.config.reset();
  o.card = BoardKind::I7i96s;
  o.amplifiers = {{0, 0}};
  EXPECT_THROW(BoardServer{o}, UsageError) << "no 8I20 on channel 1 of the 7I96S";
  o.motors[0].channel = 0;
  BoardServer on_7i96s(o);
  EXPECT_EQ(on_7i96s.motor_axes()[0].axis, 0u);
}
