// SPDX-License-Identifier: GPL-2.0-or-later
// Hall sensors over electrical turns: the codes bldc expects (its default pattern 25),
// 120 and 60 degree layouts, polarity, wiring order and faults.
#include "ethsim/hall_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "error/error.hpp"

using namespace i20;
using namespace i20::ethsim;

namespace {

// Codes seen, in order, over one electrical turn sampled in the middle of each sixth,
// starting at `start_degrees`.
std::vector<unsigned> sequence(const HallSensors& h, double start_degrees = 0.0) {
  std::vector<unsigned> out;
  const double per_electrical = 1.0 / h.spec().pole_pairs;
  for (int sector = 0; sector < 6; ++sector)
    out.push_back(h.code((start_degrees + 60.0 * sector) / 360.0 * per_electrical));
  return out;
}

// Count the code changes over one mechanical turn.
int transitions_per_turn(const HallSensors& h) {
  int changes = 0;
  unsigned last = h.code(0.0);
  for (int i = 1; i <= 36000; ++i) {
    const unsigned c = h.code(i / 36000.0);
    if (c != last) ++changes;
    last = c;
  }
  return changes;
}

}  // namespace

TEST(HallModel, DefaultsGiveBldcPattern25AtTheSectorCentres) {
  // bldc's default pattern 25: 001 -> 0, 101 -> 60, 100 -> 120, 110 -> 180, 010 -> 240,
  // 011 -> 300 degrees (sector centres; H1 is the high bit).
  const HallSensors h(HallSpec{.pole_pairs = 1});
  EXPECT_EQ(sequence(h), (std::vector<unsigned>{0b001, 0b101, 0b100, 0b110, 0b010, 0b011}));
}

TEST(HallModel, PolePairsAndOffsetScaleTheElectricalAngle) {
  const HallSensors h(HallSpec{.pole_pairs = 4, .electrical_offset_turns = 0.25});
  EXPECT_DOUBLE_EQ(h.electrical_turns(0.5), 2.25);
  EXPECT_EQ(transitions_per_turn(h), 24) << "six per electrical turn";
  // A quarter turn of electrical offset moves the 90-degree code (100) to the rotor's zero.
  const HallSensors reference(HallSpec{.pole_pairs = 4});
  EXPECT_EQ(h.code(0.0), reference.code(0.25 / 4));
}

TEST(HallModel, Layout120NeverShowsAllOrNone) {
  const HallSensors h(HallSpec{.pole_pairs = 1});
  std::set<unsigned> seen;
  for (int i = 0; i < 3600; ++i) seen.insert(h.code(i / 3600.0));
  EXPECT_EQ(seen, (std::set<unsigned>{1, 2, 3, 4, 5, 6}));
}

TEST(HallModel, Layout60ShowsAllAndNoneButNeither010Nor101) {
  const HallSensors h(HallSpec{.pole_pairs = 1, .first_rise_turns = 0.0, .layout = HallLayout::Spaced60});
  std::set<unsigned> seen;
  for (int i = 0; i < 3600; ++i) seen.insert(h.code(i / 3600.0));
  EXPECT_EQ(seen, (std::set<unsigned>{0b000, 0b001, 0b011, 0b100, 0b110, 0b111}));
  EXPECT_EQ(sequence(h, 30.0), (std::vector<unsigned>{0b100, 0b110, 0b111, 0b011, 0b001, 0b000}));
}

TEST(HallModel, InvertedPolarityComplementsEveryCode) {
  const HallSensors normal(HallSpec{.pole_pairs = 2});
  const HallSensors inverted(HallSpec{.pole_pairs = 2, .inverted = true});
  for (int i = 0; i < 720; ++i) EXPECT_EQ(inverted.code(i / 720.0), 7u - normal.code(i / 720.0)) << i;
}

TEST(HallModel, SwappedWiringRunsTheSequenceBackwards) {
  const HallSensors normal(HallSpec{.pole_pairs = 1});
  const HallSensors swapped(HallSpec{.pole_pairs = 1, .order = {0, 2, 1}});
  const auto forward = sequence(normal);
  const auto reordered = sequence(swapped);
  // Swapping H2 and H3 maps the forward sequence onto itself read backwards (up to a shift).
  std::set<std::vector<unsigned>> rotations_of_reversed;
  std::vector<unsigned> reversed(forward.rbegin(), forward.rend());
  for (int k = 0; k < 6; ++k) {
    std::rotate(reversed.begin(), reversed.begin() + 1, reversed.end());
    rotations_of_reversed.insert(reversed);
  }
  std::vector<unsigned> swapped_codes;
  for (unsigned c : forward) swapped_codes.push_back((c & 0b100) | (c & 0b010) >> 1 | (c & 0b001) << 1);
  EXPECT_EQ(reordered, swapped_codes);
  EXPECT_TRUE(rotations_of_reversed.count(reordered)) << "the same cycle, run the other way";
}

TEST(HallModel, StuckAndMissingSensors) {
  HallSensors h(HallSpec{.pole_pairs = 1});
  h.set_fault(0, HallFault::StuckHigh);
  h.set_fault(1, HallFault::StuckLow);
  h.set_fault(2, HallFault::Missing);
  for (int i = 0; i < 36; ++i) {
    const auto out = h.outputs(i / 36.0);
    EXPECT_EQ(out[0], HallOutput::High);
    EXPECT_EQ(out[1], HallOutput::Low);
    EXPECT_EQ(out[2], HallOutput::Open);
  }
  EXPECT_EQ(h.code(0.3, /*open_reads=*/true), 0b101u);
  EXPECT_EQ(h.code(0.3, /*open_reads=*/false), 0b100u);
  h.set_fault(0, HallFault::None);
  EXPECT_EQ(h.outputs(0.0)[0], HallOutput::Low) << "sensor 1 is low at 0 degrees again";
  EXPECT_THROW(h.set_fault(3, HallFault::StuckHigh), UsageError);
}

TEST(HallModel, RejectsABadSpec) {
  EXPECT_THROW(HallSensors(HallSpec{.pole_pairs = 0}), UsageError);
  EXPECT_THROW(HallSensors(HallSpec{.order = {0, 0, 1}}), UsageError);
}
