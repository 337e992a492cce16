// SPDX-License-Identifier: GPL-2.0-or-later
// The HostMot2 quadrature counter (GTag 4) as LinuxCNC's hostmot2 driver reads it, fed by
// an incremental encoder on a shaft (docs/virtual-feedback.md). Pure: time is the card's
// clock given by the caller, nothing here reads a clock or does I/O.
//
//   TimestampCounter ts(100'000'000);           // ClockLow of the card
//   EncoderChannel enc(EncoderSpec{.counts_per_turn = 2000});
//   enc.move_to(0.25, 1ms, ts);                 // the shaft turned a quarter turn by 1 ms
//   enc.count_register();                       // 500 | TSCount at the last edge << 16
#pragma once

#include <chrono>
#include <cstdint>

namespace i20::ethsim {

// Time on the card's clock since it started.
using BoardTime = std::chrono::nanoseconds;

// TSCount: a free-running 16-bit counter at ClockLow / (TSDiv + 2); a TSDiv with bit 15
// set divides by 1 (FW regmap). One per encoder module, shared by its instances.
class TimestampCounter {
 public:
  explicit TimestampCounter(std::uint32_t clock_low_hz) : clock_low_hz_(clock_low_hz) {}

  std::uint16_t count_at(BoardTime t) const;
  // The host writes TSDiv at `t`: the counter keeps its value and runs at the new rate.
  void write_divider(std::uint32_t value, BoardTime t);
  std::uint32_t divider_register() const { return divider_; }
  // Clock cycles per TSCount tick.
  std::uint64_t cycles_per_tick() const;

 private:
  std::int64_t cycles_at(BoardTime t) const;
  std::int64_t ticks_at(BoardTime t) const;

  std::uint32_t clock_low_hz_;
  std::uint32_t divider_ = 0;
  std::int64_t reference_cycles_ = 0;  // the clock when the divider was last written
  std::int64_t reference_ticks_ = 0;   // TSCount (unwrapped) then
};

// The encoder on the shaft. One count is one quadrature state (4 counts per line), so
// `counts_per_turn` = 4 x lines per revolution and must be a positive multiple of 4.
struct EncoderSpec {
  std::int32_t counts_per_turn = 2000;  // a 500-line encoder
  // +1: the count rises with the shaft angle (A leads B); -1: it falls.
  int direction = +1;
  bool has_index = true;
  // Mechanical angle (turns) of the index pulse, which is one count wide: Z is high while
  // the shaft is in the count that holds this angle.
  double index_turns = 0.0;
};

enum class EncoderFault {
  None,
  // The encoder's signals stop changing (cable off, encoder dead): no counts, no index.
  Lost,
  // Every count edge also sets the quadrature error bit, as a noisy line would.
  QuadratureError,
};

// One instance of the counter: its count and latch/control registers.
class EncoderChannel {
 public:
  explicit EncoderChannel(EncoderSpec spec);  // throws UsageError on a bad spec

  // The shaft is at `turns` (mechanical, unwrapped) at card time `t`. The first call only
  // places the encoder. Later calls step through every count between the previous sample
  // and this one, giving each edge its time by linear interpolation, so timestamps and
  // index events fall between host reads where they belong. `t` must not go back.
  void move_to(double turns, BoardTime t, const TimestampCounter& ts);

  // Register 0: count in bits 0-15, TSCount at the last count change in bits 16-31.
  std::uint32_t count_register() const;
  // A host write to register 0 clears the count (the timestamp stays).
  void write_count();
  // Register 1: latched count in bits 16-31; control bits, quad error and live A/B/Z below.
  std::uint32_t latch_control_register() const;
  // A host write sets the control bits 3-14 and clears the quad error (bit 15: hostmot2
  // clears a reported error by rewriting the register with the bit clear). Bits 0-2 are
  // read only.
  void write_latch_control(std::uint32_t value);

  void set_fault(EncoderFault fault) { fault_ = fault; }
  EncoderFault fault() const { return fault_; }
  const EncoderSpec& spec() const { return spec_; }

  // The encoder's signals now.
  bool a() const;
  bool b() const;
  bool z() const;
  // Quadrature state number (unwrapped): the count an ideal counter would hold since the
  // shaft's zero, with the encoder's direction applied.
  std::int64_t state() const { return state_; }
  std::uint16_t count() const { return count_; }

 private:
  void step(int delta, BoardTime at, const TimestampCounter& ts);
  bool index_accepted() const;
  static bool a_of(std::int64_t state);
  static bool b_of(std::int64_t state);
  bool z_of(std::int64_t state) const;

  EncoderSpec spec_;
  EncoderFault fault_ = EncoderFault::None;
  bool placed_ = false;
  bool frozen_ = false;       // the last sample found the encoder lost
  double last_position_ = 0;  // counts (direction applied), fractional
  BoardTime last_time_{0};
  std::int64_t state_ = 0;
  std::int64_t index_state_ = 0;  // a state where Z is high (modulo counts_per_turn)
  std::uint16_t count_ = 0;
  std::uint16_t timestamp_ = 0;
  std::uint16_t latched_ = 0;
  std::uint32_t control_ = 0;  // bits 3-14 as written (4 and 5 cleared by a JustOnce event)
  bool quad_error_ = false;
};

}  // namespace i20::ethsim
