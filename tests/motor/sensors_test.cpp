// SPDX-License-Identifier: GPL-2.0-or-later
// What the encoder and Hall sensors read for a rotor angle.
#include "motor/sensors.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <set>

using namespace i20::motor;

namespace {
constexpr double kDeg = std::numbers::pi / 180;

int bits_changed(unsigned a, unsigned b) {
  return __builtin_popcount(a ^ b);
}
}  // namespace

TEST(Encoder, CountsFollowTheDirection) {
  EncoderDescription e{10000, 1, 0};
  EXPECT_EQ(encoder_count(e, 0.25), 2500);
  EXPECT_EQ(encoder_count(e, -0.25), -2500);
  e.direction = -1;
  EXPECT_EQ(encoder_count(e, 0.25), -2500);
}

TEST(Halls, A120DegreePlacementIsASixStepGrayCycle) {
  HallDescription h;
  std::set<unsigned> codes;
  unsigned previous = hall_code(h, 5 * kDeg);
  for (int sector = 1; sector <= 6; ++sector) {
    const unsigned code = hall_code(h, (5 + 60 * sector) * kDeg);
    EXPECT_EQ(bits_changed(previous, code), 1) << sector;
    codes.insert(code);
    previous = code;
  }
  EXPECT_EQ(codes.size(), 6u);
  EXPECT_FALSE(codes.contains(0u));
  EXPECT_FALSE(codes.contains(7u));
}

TEST(Halls, Pattern25ReadsBldcsDocumentedCodes) {
  HallDescription h;
  h.bldc_pattern = 25;
  EXPECT_EQ(hall_code(h, 0), 0b001u);
  EXPECT_EQ(hall_code(h, 60 * kDeg), 0b101u);
  EXPECT_EQ(hall_code(h, 180 * kDeg), 0b110u);
  EXPECT_EQ(hall_code(h, -60 * kDeg), 0b011u);
  h.polarity = HallPolarity::ActiveLow;
  EXPECT_EQ(hall_code(h, 0), 0b110u);
}
