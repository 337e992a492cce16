// SPDX-License-Identifier: GPL-2.0-or-later
#include "motor/sensors.hpp"

#include <cmath>
#include <numbers>

namespace i20::motor {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kDefaultBldcPattern = 25;

// bldc's pattern 25 as LinuxCNC's bldc(9) documents it: the Hall code read in the 60-degree
// electrical sector centred on 0, 60, ..., 300 degrees (H1 H2 H3 as bits 2 1 0).
constexpr unsigned kPattern25[6] = {0b001, 0b101, 0b100, 0b110, 0b010, 0b011};

double wrap(double angle) {
  const double a = std::fmod(angle, kTwoPi);
  return a < 0 ? a + kTwoPi : a;
}

unsigned placed_code(const HallDescription& h, double electrical) {
  // 120-degree placement: sensor k is active for half a turn starting at offset + k*120.
  // 60-degree placement: sensors at 0, 60, 120; the middle one is the inverse of a
  // 120-degree sensor at 240 (the usual 60-degree wiring), so the codes differ.
  const double spacing = h.placement == HallPlacement::Deg120 ? kTwoPi / 3 : kTwoPi / 6;
  unsigned code = 0;
  for (int k = 0; k < 3; ++k) {
    const bool active = wrap(electrical - h.offset_rad - k * spacing) < std::numbers::pi;
    code = (code << 1) | (active ? 1u : 0u);
  }
  return code;
}

}  // namespace

bool known_bldc_pattern(int pattern) {
  return pattern == kDefaultBldcPattern;
}

std::int64_t encoder_count(const EncoderDescription& e, double turns) {
  const auto counts = static_cast<std::int64_t>(std::floor(turns * static_cast<double>(e.counts_per_turn)));
  return e.direction < 0 ? -counts : counts;
}

unsigned hall_code(const HallDescription& h, double electrical_angle_rad) {
  unsigned code = 0;
  if (h.bldc_pattern) {
    const double sector = std::floor(wrap(electrical_angle_rad + kTwoPi / 12) / (kTwoPi / 6));
    code = kPattern25[static_cast<int>(sector) % 6];
  } else {
    code = placed_code(h, electrical_angle_rad);
  }
  return h.polarity == HallPolarity::ActiveLow ? (~code & 7u) : code;
}

}  // namespace i20::motor
