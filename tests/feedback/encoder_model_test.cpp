// SPDX-License-Identifier: GPL-2.0-or-later
// The quadrature counter model against what LinuxCNC's hostmot2 driver reads from it
// (hm2/encoder.c) and the firmware register map: counts, timestamps, TSCount, index latch.
#include "ethsim/encoder_model.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "error/error.hpp"
#include "hostmot2/hostmot2.hpp"

using namespace i20;
using namespace i20::ethsim;
using namespace std::chrono_literals;
namespace bit = i20::lbp::hm2::encoder_bit;

namespace {

constexpr std::uint32_t kClockLow = 100'000'000;
// What hm2 writes: TSDiv = ClockLow / 2 MHz - 2, so TSCount ticks every 500 ns.
constexpr std::uint32_t kHm2TsDiv = kClockLow / 2'000'000 - 2;
constexpr std::uint32_t kArmIndex = bit::kLatchOnIndex | bit::kJustOnce;

struct Rig {
  TimestampCounter ts{kClockLow};
  EncoderChannel enc;
  explicit Rig(EncoderSpec spec = {}) : enc(spec) {
    ts.write_divider(kHm2TsDiv, 0ns);
    enc.move_to(0.0, 0ns, ts);
  }
  std::int16_t count() const { return static_cast<std::int16_t>(enc.count_register() & 0xFFFF); }
  std::uint16_t timestamp() const { return static_cast<std::uint16_t>(enc.count_register() >> 16); }
  std::uint32_t control() const { return enc.latch_control_register(); }
  std::uint16_t latched() const { return static_cast<std::uint16_t>(control() >> 16); }
};

// Turns placing the shaft in the middle of quadrature state `state` of a 2000-count encoder.
double mid_state(int state, int counts_per_turn = 2000) {
  return (state + 0.5) / counts_per_turn;
}

}  // namespace

TEST(EncoderModel, CountsFollowTheShaftInBothDirections) {
  Rig r(EncoderSpec{.counts_per_turn = 2000});
  r.enc.move_to(0.25, 1ms, r.ts);
  EXPECT_EQ(r.count(), 500);
  r.enc.move_to(-0.1, 2ms, r.ts);
  EXPECT_EQ(r.count(), -200);
  r.enc.move_to(3.7, 3ms, r.ts);  // 7,400 counts in one sample: every one stepped through
  EXPECT_EQ(r.count(), 7400);
  EXPECT_EQ(r.control() & bit::kQuadError, 0u) << "no false quadrature error";
}

TEST(EncoderModel, DirectionMinusOneCountsDown) {
  Rig r(EncoderSpec{.counts_per_turn = 4096, .direction = -1});
  r.enc.move_to(0.5, 1ms, r.ts);
  EXPECT_EQ(r.count(), -2048);
}

TEST(EncoderModel, ALeadsBWhenCountingUp) {
  // hostmot2 counts up when A leads B: states 0..3 are AB = 00, 10, 11, 01.
  Rig r;
  const std::uint32_t ab = bit::kInputA | bit::kInputB;
  const std::uint32_t expected[] = {0, bit::kInputA, ab, bit::kInputB, 0};
  for (int s = 0; s <= 4; ++s) {
    r.enc.move_to(mid_state(s), std::chrono::milliseconds(s + 1), r.ts);
    EXPECT_EQ(r.control() & ab, expected[s]) << "state " << s;
  }
}

TEST(EncoderModel, IndexIsOneCountWideAtItsAngle) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.1});  // the count 200..201
  r.enc.move_to(mid_state(199), 1ms, r.ts);
  EXPECT_EQ(r.control() & bit::kInputIndex, 0u);
  r.enc.move_to(mid_state(200), 2ms, r.ts);
  EXPECT_NE(r.control() & bit::kInputIndex, 0u);
  r.enc.move_to(mid_state(201), 3ms, r.ts);
  EXPECT_EQ(r.control() & bit::kInputIndex, 0u);
  r.enc.move_to(1.0 + mid_state(200), 4ms, r.ts);  // once per turn
  EXPECT_NE(r.control() & bit::kInputIndex, 0u);
}

TEST(EncoderModel, TimestampIsTsCountAtTheLastEdge) {
  Rig r;
  // 10.5 counts at constant speed over 1 ms: the last edge (count 10) at 10/10.5 ms.
  r.enc.move_to(10.5 / 2000, 1ms, r.ts);
  EXPECT_EQ(r.count(), 10);
  const double edge_ns = std::round(10.0 / 10.5 * 1e6);
  const auto expected = static_cast<std::uint16_t>(std::floor(edge_ns / 500.0));  // 2 MHz ticks
  EXPECT_EQ(r.timestamp(), expected);
  EXPECT_NE(r.timestamp(), r.ts.count_at(1ms)) << "not the time of the sample";
  // No new edge: the timestamp stays while TSCount runs on.
  r.enc.move_to(10.9 / 2000, 5ms, r.ts);
  EXPECT_EQ(r.timestamp(), expected);
  EXPECT_EQ(r.ts.count_at(5ms), 10000);
}

TEST(EncoderModel, TsCountRunsAtClockLowOverTsDivPlusTwo) {
  TimestampCounter ts(kClockLow);
  ts.write_divider(48, 0ns);  // 100 MHz / 50 = 2 MHz
  EXPECT_EQ(ts.count_at(1ms), 2000);
  ts.write_divider(8, 1ms);  // 100 MHz / 10 = 10 MHz from here
  EXPECT_EQ(ts.count_at(2ms), 2000 + 10000);
  EXPECT_EQ(ts.count_at(7ms), (2000 + 60000) % 65536) << "16 bits, wraps";
  ts.write_divider(0x8000, 7ms);  // bit 15 set: divide by one
  EXPECT_EQ(ts.count_at(7ms + 100us), (2000 + 60000 + 10000) % 65536);
  EXPECT_EQ(ts.divider_register(), 0x8000u);
}

TEST(EncoderModel, IndexLatchWithJustOnceAsHostmot2ArmsIt) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.1});
  r.enc.write_latch_control(kArmIndex);  // index-invert 0: the falling edge is the event
  r.enc.move_to(0.05, 1ms, r.ts);
  EXPECT_NE(r.control() & bit::kLatchOnIndex, 0u) << "bit 4 reads 1 until the index";
  r.enc.move_to(0.3, 2ms, r.ts);
  EXPECT_EQ(r.control() & bit::kLatchOnIndex, 0u) << "bit 4 reads 0 after it";
  EXPECT_EQ(r.latched(), 201) << "the count as Z fell, leaving the index count";
  r.enc.move_to(1.3, 3ms, r.ts);  // the next index does not latch again
  EXPECT_EQ(r.latched(), 201);
  EXPECT_EQ(r.count(), 2600);
  r.enc.write_latch_control(kArmIndex);  // re-armed
  EXPECT_NE(r.control() & bit::kLatchOnIndex, 0u);
  r.enc.move_to(2.3, 4ms, r.ts);
  EXPECT_EQ(r.control() & bit::kLatchOnIndex, 0u);
  EXPECT_EQ(r.latched(), 4201);
}

TEST(EncoderModel, IndexPolarityPicksTheRisingEdge) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.1});
  r.enc.write_latch_control(kArmIndex | bit::kIndexPolarity);  // index-invert 1
  r.enc.move_to(0.3, 1ms, r.ts);
  EXPECT_EQ(r.latched(), 200) << "the count as Z rose";
}

TEST(EncoderModel, IndexLatchTurningBackwards) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.1});
  r.enc.move_to(0.2, 1ms, r.ts);  // count 400, past the index
  r.enc.write_latch_control(kArmIndex);
  r.enc.move_to(0.0, 2ms, r.ts);
  EXPECT_EQ(r.control() & bit::kLatchOnIndex, 0u);
  EXPECT_EQ(r.latched(), 199) << "Z falls as the shaft leaves the index count downwards";
}

TEST(EncoderModel, LatchWithoutJustOnceStaysArmed) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.1});
  r.enc.write_latch_control(bit::kLatchOnIndex);
  r.enc.move_to(1.3, 1ms, r.ts);
  EXPECT_NE(r.control() & bit::kLatchOnIndex, 0u);
  EXPECT_EQ(r.latched(), 2201) << "the last index passed";
}

TEST(EncoderModel, ClearOnIndexZeroesTheCount) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.1});
  r.enc.write_latch_control(bit::kClearOnIndex | bit::kJustOnce);
  r.enc.move_to(0.3, 1ms, r.ts);
  EXPECT_EQ(r.count(), 600 - 201);
  EXPECT_EQ(r.control() & bit::kClearOnIndex, 0u);
}

TEST(EncoderModel, NoIndexWhenTheEncoderHasNone) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .has_index = false});
  r.enc.write_latch_control(kArmIndex);
  r.enc.move_to(3.0, 1ms, r.ts);
  EXPECT_NE(r.control() & bit::kLatchOnIndex, 0u);
}

TEST(EncoderModel, SixteenBitCountWrapsAndExtendsLikeHostmot2) {
  Rig r(EncoderSpec{.counts_per_turn = 4000});
  // hostmot2 extends the 16-bit count by the signed difference since its last read.
  std::int64_t rawcounts = 0;
  std::uint16_t previous = 0;
  for (int period = 1; period <= 80; ++period) {  // 20 turns, 1,000 counts per read
    r.enc.move_to(period * 0.25, std::chrono::milliseconds(period), r.ts);
    const auto now = static_cast<std::uint16_t>(r.enc.count_register() & 0xFFFF);
    std::int32_t diff = now - previous;
    if (diff > 32768) diff -= 65536;
    if (diff < -32768) diff += 65536;
    rawcounts += diff;
    previous = now;
  }
  EXPECT_EQ(rawcounts, 80000);
  EXPECT_EQ(r.enc.count_register() & 0xFFFF, 80000u % 65536u);
}

TEST(EncoderModel, WritingTheCountRegisterClearsIt) {
  Rig r;
  r.enc.move_to(0.1, 1ms, r.ts);
  r.enc.write_count();
  EXPECT_EQ(r.count(), 0);
  r.enc.move_to(0.2, 2ms, r.ts);
  EXPECT_EQ(r.count(), 200);
}

TEST(EncoderModel, LostEncoderStopsCountingAndReportsTheJumpWhenBack) {
  Rig r;
  r.enc.move_to(0.1, 1ms, r.ts);
  r.enc.set_fault(EncoderFault::Lost);
  r.enc.move_to(0.5, 2ms, r.ts);
  EXPECT_EQ(r.count(), 200);
  const std::uint32_t frozen = r.control() & 0x7;
  r.enc.move_to(0.5 + mid_state(1), 3ms, r.ts);
  EXPECT_EQ(r.control() & 0x7, frozen) << "A/B/Z freeze";
  r.enc.set_fault(EncoderFault::None);
  r.enc.move_to(0.6, 4ms, r.ts);
  EXPECT_EQ(r.count(), 200) << "the missed counts stay missed";
  EXPECT_NE(r.control() & bit::kQuadError, 0u);
  r.enc.move_to(0.7, 5ms, r.ts);
  EXPECT_EQ(r.count(), 400) << "counting again";
}

TEST(EncoderModel, InjectedQuadratureErrorSetsBit15UntilTheHostRewritesControl) {
  Rig r;
  r.enc.set_fault(EncoderFault::QuadratureError);
  r.enc.move_to(0.01, 1ms, r.ts);
  EXPECT_NE(r.control() & bit::kQuadError, 0u);
  r.enc.set_fault(EncoderFault::None);
  r.enc.move_to(0.02, 2ms, r.ts);
  EXPECT_NE(r.control() & bit::kQuadError, 0u) << "sticky";
  r.enc.write_latch_control(bit::kFilter);  // hostmot2 clears it by rewriting control
  EXPECT_EQ(r.control() & bit::kQuadError, 0u);
  EXPECT_NE(r.control() & bit::kFilter, 0u);
}

TEST(EncoderModel, ReadOnlyBitsIgnoreWrites) {
  Rig r(EncoderSpec{.counts_per_turn = 2000, .index_turns = 0.5});
  r.enc.write_latch_control(0xFFFF'0007u);
  EXPECT_EQ(r.control() & 0x7, 0u) << "A, B, Z are live, at state 0 all low";
  EXPECT_EQ(r.latched(), 0);
}

TEST(EncoderModel, RejectsCountsThatAreNotFourPerLine) {
  EXPECT_THROW(EncoderChannel(EncoderSpec{.counts_per_turn = 1001}), UsageError);
  EXPECT_THROW(EncoderChannel(EncoderSpec{.counts_per_turn = 0}), UsageError);
  EXPECT_THROW(EncoderChannel(EncoderSpec{.direction = 2}), UsageError);
}
