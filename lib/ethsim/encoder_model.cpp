// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/encoder_model.hpp"

#include <cmath>
#include <cstdlib>

#include "error/error.hpp"
#include "hostmot2/hostmot2.hpp"

namespace i20::ethsim {

namespace bit = lbp::hm2::encoder_bit;

namespace {

constexpr std::int64_t kNanosecondsPerSecond = 1'000'000'000;
// Bits 3-14 of the latch/control register are the host's.
constexpr std::uint32_t kWritableControl = 0x7FF8;
// A jump of more counts than this between two samples is not stepped through: a real
// counter would have lost it too (quad error), and stepping would take seconds.
constexpr std::int64_t kMaxCountsPerSample = std::int64_t{1} << 22;

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

std::int64_t floor_mod(std::int64_t a, std::int64_t b) {
  return a - floor_div(a, b) * b;
}

}  // namespace

// ---- TimestampCounter -------------------------------------------------------------------

std::int64_t TimestampCounter::cycles_at(BoardTime t) const {
  const std::int64_t ns = t.count();
  const std::int64_t seconds = floor_div(ns, kNanosecondsPerSecond);
  const std::int64_t rest = ns - seconds * kNanosecondsPerSecond;  // < 1e9: rest * clock fits
  return seconds * clock_low_hz_ + rest * std::int64_t{clock_low_hz_} / kNanosecondsPerSecond;
}

std::uint64_t TimestampCounter::cycles_per_tick() const {
  return (divider_ & 0x8000u) != 0 ? 1u : (divider_ & 0xFFFFu) + 2u;
}

std::int64_t TimestampCounter::ticks_at(BoardTime t) const {
  return reference_ticks_ +
         floor_div(cycles_at(t) - reference_cycles_, static_cast<std::int64_t>(cycles_per_tick()));
}

std::uint16_t TimestampCounter::count_at(BoardTime t) const {
  return static_cast<std::uint16_t>(floor_mod(ticks_at(t), 0x10000));
}

void TimestampCounter::write_divider(std::uint32_t value, BoardTime t) {
  reference_ticks_ = ticks_at(t);
  reference_cycles_ = cycles_at(t);
  divider_ = value & 0xFFFFu;
}

// ---- EncoderChannel ---------------------------------------------------------------------

EncoderChannel::EncoderChannel(EncoderSpec spec) : spec_(spec) {
  if (spec_.counts_per_turn <= 0 || spec_.counts_per_turn % 4 != 0)
    throw UsageError("an encoder's counts per turn must be a positive multiple of 4 (4 x lines), got " +
                     std::to_string(spec_.counts_per_turn));
  if (spec_.direction != 1 && spec_.direction != -1)
    throw UsageError("an encoder's direction is +1 or -1, got " + std::to_string(spec_.direction));
  if (!std::isfinite(spec_.index_turns)) throw UsageError("the encoder's index angle is not a number");
  index_state_ = static_cast<std::int64_t>(
      std::floor(spec_.direction * spec_.index_turns * static_cast<double>(spec_.counts_per_turn)));
}

bool EncoderChannel::a_of(std::int64_t state) {
  const std::int64_t q = floor_mod(state, 4);
  return q == 1 || q == 2;
}

bool EncoderChannel::b_of(std::int64_t state) {
  const std::int64_t q = floor_mod(state, 4);
  return q == 2 || q == 3;
}

bool EncoderChannel::z_of(std::int64_t state) const {
  return spec_.has_index && floor_mod(state - index_state_, spec_.counts_per_turn) == 0;
}

bool EncoderChannel::a() const {
  return a_of(state_);
}
bool EncoderChannel::b() const {
  return b_of(state_);
}
bool EncoderChannel::z() const {
  return z_of(state_);
}

void EncoderChannel::move_to(double turns, BoardTime t, const TimestampCounter& ts) {
  if (!std::isfinite(turns)) return;
  const double position = spec_.direction * turns * static_cast<double>(spec_.counts_per_turn);
  const auto target = static_cast<std::int64_t>(std::floor(position));
  const bool lost = fault_ == EncoderFault::Lost;
  const bool jump = std::llabs(target - state_) > kMaxCountsPerSample;
  if (!placed_ || lost || frozen_ || jump) {
    // Placed without counting. While lost the signals freeze; a counter that sees them come
    // back (or jump) elsewhere has missed transitions: that is a quadrature error.
    if (placed_ && !lost && std::llabs(target - state_) > 1) quad_error_ = true;
    if (!placed_ || !lost) state_ = target;
    placed_ = true;
    frozen_ = lost;
    last_position_ = position;
    last_time_ = t;
    return;
  }
  const double from = last_position_;
  const auto span = static_cast<double>((t - last_time_).count());
  const auto edge_time = [&](double boundary) {
    const double fraction = position == from ? 1.0 : (boundary - from) / (position - from);
    return last_time_ + BoardTime(static_cast<std::int64_t>(std::llround(fraction * span)));
  };
  while (state_ < target) step(+1, edge_time(static_cast<double>(state_ + 1)), ts);
  while (state_ > target) step(-1, edge_time(static_cast<double>(state_)), ts);
  last_position_ = position;
  last_time_ = t;
}

bool EncoderChannel::index_accepted() const {
  // The index-mask input is not wired on the virtual cards and reads low.
  const bool mask_input = false;
  if ((control_ & bit::kIndexMask) != 0 && mask_input != ((control_ & bit::kIndexMaskPolarity) != 0))
    return false;
  if ((control_ & bit::kAbGateIndex) != 0) {
    // Gate with A and B as they are while Z is high (the index state).
    const bool ab = a_of(index_state_) && b_of(index_state_);
    if (ab != ((control_ & bit::kAbMaskPolarity) != 0)) return false;
  }
  return true;
}

void EncoderChannel::step(int delta, BoardTime at, const TimestampCounter& ts) {
  const std::int64_t before = state_;
  state_ += delta;
  int count_change = delta;
  if ((control_ & bit::kCounterMode) != 0) {
    // Up/down mode: A is the count, B the direction (high = up, our choice).
    const bool a_rose = !a_of(before) && a_of(state_);
    count_change = a_rose ? (b_of(state_) ? +1 : -1) : 0;
  }
  if (count_change != 0) {
    count_ = static_cast<std::uint16_t>(count_ + count_change);
    timestamp_ = ts.count_at(at);
  }
  if (fault_ == EncoderFault::QuadratureError) quad_error_ = true;

  // Index event: the rising edge of Z with IndexPolarity set, the falling edge without.
  const bool z_before = z_of(before);
  const bool z_after = z_of(state_);
  const bool rising_is_event = (control_ & bit::kIndexPolarity) != 0;
  const bool event = z_before != z_after && z_after == rising_is_event;
  if (!event || !index_accepted()) return;
  if ((control_ & bit::kLatchOnIndex) != 0) latched_ = count_;
  if ((control_ & bit::kClearOnIndex) != 0) count_ = 0;
  if ((control_ & bit::kJustOnce) != 0)
    control_ &= ~(bit::kLatchOnIndex | bit::kClearOnIndex | bit::kLatchOnProbe);
}

std::uint32_t EncoderChannel::count_register() const {
  return std::uint32_t{timestamp_} << 16 | count_;
}

void EncoderChannel::write_count() {
  count_ = 0;
}

std::uint32_t EncoderChannel::latch_control_register() const {
  std::uint32_t value = std::uint32_t{latched_} << 16 | (control_ & kWritableControl);
  if (quad_error_) value |= bit::kQuadError;
  if (a()) value |= bit::kInputA;
  if (b()) value |= bit::kInputB;
  if (z()) value |= bit::kInputIndex;
  return value;
}

void EncoderChannel::write_latch_control(std::uint32_t value) {
  control_ = value & kWritableControl;
  quad_error_ = false;
}

}  // namespace i20::ethsim
