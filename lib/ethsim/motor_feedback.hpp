// SPDX-License-Identifier: GPL-2.0-or-later
// A virtual 8I20's motor behind the virtual card's feedback inputs: the axis whose SSERIAL
// port and channel are that 8I20's gets the motor's encoder and Hall sensors, as the motor
// file describes them, turning with the motor's rotor (docs/virtual-feedback.md, "A motor
// behind an axis"). So LinuxCNC's hostmot2 + bldc see the rotor the 8I20 is driving.
#pragma once

#include <optional>

#include "ethsim/feedback_bank.hpp"
#include "ethsim/virtual_board.hpp"
#include "motor/params.hpp"
#include "sim/virtual_8i20.hpp"

namespace i20::ethsim {

// The card's encoder model for the motor file's encoder (counts, direction, index angle).
EncoderSpec encoder_spec(const motor::EncoderDescription& encoder);
// The card's Hall model for the motor file's Halls, in the motor model's electrical frame
// (electrical 0 at mechanical 0), so the code read is the one motor::hall_code() gives.
// Throws UsageError when the Halls' `inputs` are not the axis's three inputs 0, 1, 2.
HallSpec hall_spec(const motor::MotorParams& motor);

// Connects the motor on `amplifier` (the 8I20 on SSERIAL `port`, `channel`) to the card's
// axis with that port and channel: its encoder and/or Halls, as far as the motor has them.
// Each sensor reads the rotor's angle at a card time, moved on from the motor's last state
// at its speed (cheap; the motor itself advances with the card), or, while the motor's
// encoder-lost or hall-stuck fault is on, where that sensor froze. The amplifier must
// outlive the card's use of them (it lives in the card).
// Returns the axis number, or nullopt when the card has no axis for that 8I20 or the
// amplifier no motor (nothing is connected then).
std::optional<unsigned> connect_motor_feedback(VirtualBoard& board, const sim::Virtual8i20& amplifier,
                                               unsigned port, unsigned channel);

}  // namespace i20::ethsim
