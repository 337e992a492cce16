// SPDX-License-Identifier: GPL-2.0-or-later
// Puts a virtual 8I20 at the end of a simulated serial line, in real (or any) time.
// Without emulation bytes reach the card the moment they are written and replies are
// readable as soon as the card produces them. With emulation each byte takes 10 bit
// times at the card's baud in each direction, and every reply burst waits a fixed
// turnaround (a USB serial adapter adds about 1 ms), so benchmarks measure physics,
// not memcpy. Not thread-safe: SimStream and the i20sim server serialise access.
#pragma once

#include <chrono>
#include <deque>
#include <optional>

#include "lbp/bytes.hpp"
#include "sim/virtual_8i20.hpp"

namespace i20::sim {

struct WireOptions {
  bool emulate_wire_time = false;
  Duration turnaround{};  // added before each reply burst, also without wire-time emulation
};

class WireModel {
 public:
  WireModel(Virtual8i20& card, WireOptions options) : card_(card), options_(options) {}

  // The host wrote `bytes` at `now`.
  void host_write(lbp::ByteView bytes, Clock::time_point now);
  // Runs the card up to `now`: delivers bytes that have arrived, lets its timers run and
  // puts its replies on the line.
  void pump(Clock::time_point now);
  // Reply bytes that have reached the host by `now` (call pump(now) first).
  std::size_t host_read(std::span<lbp::Byte> buffer, Clock::time_point now);
  // Drops reply bytes that have reached the host and were not read (tcflush semantics).
  void discard_host_input(Clock::time_point now);
  // The next time pump() has something to do, if any.
  std::optional<Clock::time_point> next_wake() const;

  const WireOptions& options() const { return options_; }
  void set_options(const WireOptions& options) { options_ = options; }

 private:
  struct Timed {
    Clock::time_point at;
    lbp::Byte byte;
  };
  void collect_output(Clock::time_point t);

  Virtual8i20& card_;
  WireOptions options_;
  std::deque<Timed> to_card_;  // bytes on their way to the card
  std::deque<Timed> to_host_;  // reply bytes on their way to the host
  Clock::time_point line_to_card_free_{};
  Clock::time_point line_to_host_free_{};
  Clock::time_point card_time_{};
};

}  // namespace i20::sim
