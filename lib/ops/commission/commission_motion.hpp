// SPDX-License-Identifier: GPL-2.0-or-later
// The moving half of `i20 commission`, inside lib/ops: one DriveLoop cycle at a time with
// every guard checked after each, the counters unwrapped and every cycle recorded.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "eth/drive_loop.hpp"
#include "mechanics/excitation.hpp"
#include "ops/commission/commission.hpp"
#include "ops/core/cancel.hpp"

namespace i20::ops::commission_detail {

// tune-axis's path for its window (the plan's and the run's one construction). Throws
// UsageError naming the least window that would do.
mechanics::Excitation identification_path(const AxisIdentification& id);

// Why the motion stopped early: caught by run_commission, which zeroes the current.
class Abort : public std::runtime_error {
 public:
  Abort(StopReason reason, const std::string& message) : std::runtime_error(message), reason_(reason) {}
  StopReason reason() const { return reason_; }

 private:
  StopReason reason_;
};

// One recorded cycle.
struct Tick {
  double t_s = 0;     // the readings' time, on the card's clock (Motion::card_time_s)
  double host_s = 0;  // when the host sent the packet: the run's limits count this
  double command_turns = 0;          // where the current vector holds the rotor (the analysis' frame)
  std::vector<std::int64_t> counts;  // per encoder instance, unwrapped
  std::vector<std::optional<std::int64_t>> index_latch;  // per encoder instance
  std::vector<std::uint32_t> input_words;
  bool command_taken = true;  // the 8I20 took this cycle's current and angle (eth::DriveReading)
};

// The rotor's scale, once known: which encoder, which way, counts per electrical turn.
struct Scale {
  std::size_t encoder = 0;  // index into the encoders
  int direction = 1;
  double counts_per_electrical_turn = 0;
};

class Motion {
 public:
  Motion(eth::DriveLoop& loop, const CommissionPlan& plan, const CommissionOptions& options,
         const Cancel& cancel);

  // One cycle: q current `amps` (signed) at ANGLE `angle_turns` (the 8I20's frame), the
  // guards, the tick recorded. `command_turns` is what the rotor should follow (recorded).
  const Tick& drive(double amps, double angle_turns, double command_turns);
  // Holds the rotor at `command_turns` (current vector there: ANGLE a quarter turn behind).
  const Tick& hold(double amps, double command_turns) {
    return drive(amps, command_turns - 0.25, command_turns);
  }

  // Known scale: the guards for travel, speed and following apply from now on. `follow`:
  // the rotor should track the command from the current tick.
  void set_scale(const Scale& scale, bool follow);
  void stop_following() { follow_ = false; }
  const std::optional<Scale>& scale() const { return scale_; }

  const std::vector<Tick>& ticks() const { return ticks_; }
  const eth::DriveLoop& loop() const { return loop_; }
  double elapsed_s(std::chrono::steady_clock::time_point at) const;
  double card_time_s(const eth::DriveReading& reading, double host_s);
  // Changes of each candidate input (FeedbackMap::inputs) between ticks [from, to).
  std::vector<unsigned> input_changes(std::size_t from, std::size_t to) const;
  bool input_bit(const Tick& tick, std::size_t input) const;

 private:
  void unwrap(const eth::DriveReading& reading, Tick& tick);
  void guard(const eth::DriveReading& reading, const Tick& tick);
  void guard_motion(const Tick& tick);
  void check_for_other_host();

  eth::DriveLoop& loop_;
  const CommissionPlan& plan_;
  const CommissionOptions& options_;
  Cancel cancel_;
  std::chrono::steady_clock::time_point start_;
  std::vector<Tick> ticks_;
  std::vector<std::uint16_t> last16_;
  std::uint32_t foreign_at_start_ = 0;
  bool start_fault_clearing_ = true;  // the preflight's WATCHDOGFAULT may read on until cleared
  std::uint64_t cycles_ = 0;
  unsigned unanswered_host_checks_ = 0;
  std::optional<Scale> scale_;
  bool follow_ = false;
  std::int64_t follow_count_ = 0;
  double follow_command_ = 0;
  std::int64_t start_count_ = 0;
  std::optional<std::uint16_t> last_card_us_;  // card_time_s's timer, as last read
  double last_host_s_ = 0, card_s_ = 0;
};

}  // namespace i20::ops::commission_detail
