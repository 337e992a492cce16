// SPDX-License-Identifier: GPL-2.0-or-later
// The motor's feedback devices described as data (a motor file's `encoder:` and `halls:`),
// and what they read for a rotor angle. The register-level emulation of an encoder or Hall
// inputs on a virtual FPGA card lives with that card (lib/ethsim); these are the physics.
//
// Angles: mechanical angle 0 is the rotor position where electrical angle 0 of the first
// pole pair is, i.e. where an unloaded rotor settles with +V on phase A (U) and B+C (V+W)
// tied to -V (LinuxCNC's bldc(9) convention). Electrical angle = pole_pairs x mechanical.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

namespace i20::motor {

struct EncoderDescription {
  std::int64_t counts_per_turn = 0;  // quadrature counts (edges) per mechanical turn
  int direction = 1;                 // +1: counts up when the rotor turns forward; -1: down
  double index_angle_rad = 0;        // mechanical angle of the index pulse, from mechanical 0
};

enum class HallPlacement { Deg120, Deg60 };
enum class HallPolarity { ActiveHigh, ActiveLow };

struct HallDescription {
  // Either bldc(9)'s `pattern` number (which Hall code is read in which 60-degree sector)
  // or a placement of three ideal sensors; with a pattern, placement is ignored.
  std::optional<int> bldc_pattern;
  HallPlacement placement = HallPlacement::Deg120;
  double offset_rad = 0;  // electrical angle where Hall 1 goes active (placement only)
  HallPolarity polarity = HallPolarity::ActiveHigh;
  std::array<int, 3> inputs{0, 1, 2};  // the card's input pins Hall 1, 2, 3 are wired to
};

// The patterns hall_code() knows: bldc's default, 25 (LinuxCNC bldc.comp, pattern table).
bool known_bldc_pattern(int pattern);

// The encoder's count at this unwrapped mechanical angle (in turns): floor(turns * counts)
// times the direction. Count 0 at mechanical angle 0.
std::int64_t encoder_count(const EncoderDescription& encoder, double turns);

// The three Hall levels at this electrical angle (radians, any range) as H1 H2 H3 in bits
// 2 1 0, after polarity (an active-low sensor reads 0 when active).
unsigned hall_code(const HallDescription& halls, double electrical_angle_rad);

}  // namespace i20::motor
