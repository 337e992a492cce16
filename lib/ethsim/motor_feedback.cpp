// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/motor_feedback.hpp"

#include <cmath>
#include <numbers>

#include "error/error.hpp"

namespace i20::ethsim {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// bldc's pattern 25 (LinuxCNC bldc.comp): sensors 120 degrees apart, Hall 1 rising at 30
// electrical degrees, the HallSpec defaults (docs/virtual-feedback.md).
constexpr double kPattern25FirstRise = 1.0 / 12.0;

}  // namespace

EncoderSpec encoder_spec(const motor::EncoderDescription& encoder) {
  return EncoderSpec{.counts_per_turn = static_cast<std::int32_t>(encoder.counts_per_turn),
                     .direction = encoder.direction,
                     .has_index = true,
                     .index_turns = encoder.index_angle_rad / kTwoPi};
}

HallSpec hall_spec(const motor::MotorParams& motor) {
  const motor::HallDescription halls = motor.halls.value_or(motor::HallDescription{});
  HallSpec spec;
  spec.pole_pairs = static_cast<unsigned>(motor.pole_pairs);
  spec.electrical_offset_turns = 0.0;  // the motor model: electrical = pole pairs x mechanical
  if (halls.bldc_pattern) {
    spec.first_rise_turns = kPattern25FirstRise;
    spec.layout = HallLayout::Spaced120;
  } else {
    spec.first_rise_turns = halls.offset_rad / kTwoPi;
    spec.layout =
        halls.placement == motor::HallPlacement::Deg120 ? HallLayout::Spaced120 : HallLayout::Spaced60;
  }
  spec.inverted = halls.polarity == motor::HallPolarity::ActiveLow;
  // The motor file says which input each Hall is wired to; the card model says which
  // Hall each input carries.
  std::array<bool, 3> used{};
  for (unsigned hall = 0; hall < 3; ++hall) {
    const int input = halls.inputs[hall];
    if (input < 0 || input > 2 || used[static_cast<unsigned>(input)])
      throw UsageError("motor '" + motor.name +
                       "': halls.inputs must name the axis's inputs 0, 1, 2 once each");
    used[static_cast<unsigned>(input)] = true;
    spec.order[static_cast<unsigned>(input)] = hall;
  }
  return spec;
}

namespace {

// The shaft as one sensor sees it: the motor's, or where the sensor froze while the motor's
// fault (`motor fault encoder-lost|hall-stuck`) is on, so the card's inputs show the fault.
ShaftSource sensor_shaft(const sim::Virtual8i20& amplifier, bool motor::SensorFaults::*fault,
                         double (motor::Motor::*frozen)() const) {
  const sim::Amplifier* a = &amplifier.amplifier();
  const motor::Motor* m = amplifier.motor();
  return [a, m, fault, frozen](Clock::time_point t) {
    if (m && m->sensor_faults().*fault) return (m->*frozen)();
    return a->motor_turns_at(t).value_or(0.0);
  };
}

}  // namespace

std::optional<unsigned> connect_motor_feedback(VirtualBoard& board, const sim::Virtual8i20& amplifier,
                                               unsigned port, unsigned channel) {
  const motor::Motor* m = amplifier.motor();
  if (!m) return std::nullopt;
  const auto& axes = board.config().axes;
  for (unsigned axis = 0; axis < axes.size(); ++axis) {
    const AxisWiring& wiring = axes[axis];
    if (wiring.sserial_port != port || wiring.channel != channel) continue;
    const auto& p = m->params();
    const auto encoder_shaft =
        sensor_shaft(amplifier, &motor::SensorFaults::encoder_lost, &motor::Motor::encoder_frozen_turns);
    const auto hall_shaft =
        sensor_shaft(amplifier, &motor::SensorFaults::hall_stuck, &motor::Motor::hall_frozen_turns);
    if (p.encoder) board.feedback().connect_encoder(wiring.encoder, encoder_spec(*p.encoder), encoder_shaft);
    if (p.halls) board.feedback().connect_halls(wiring.hall_pins, hall_spec(p), hall_shaft);
    return axis;
  }
  return std::nullopt;
}

}  // namespace i20::ethsim
