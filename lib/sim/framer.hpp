// SPDX-License-Identifier: GPL-2.0-or-later
// Cuts the bytes arriving at the simulated card into commands (manual "FRAMING").
//
// Setup mode: pre-parsing (lbp::CommandSplitter) decides where a command ends, so gaps
// between its bytes are fine. Timing still keeps sync: a partial command older than
// the command timeout is dropped, and after a byte that cannot start a command the
// framer discards input until the line has been quiet for the command timeout.
//
// Operate mode: timing alone frames. A gap longer than the command timeout ends a
// packet; a packet that is not a whole number of commands (partial, or garbage) is
// dropped entirely. A command whose RPC list an earlier command of the same packet
// rewrote (RPCMEM) no longer has the length it was cut with: it and the rest of the
// packet are dropped.
//
// The receive buffer is finite: bytes beyond `capacity` are dropped and flagged.
// Timeout and overflow events are flags the device turns into LBP status bits.
#pragma once

#include <chrono>
#include <deque>
#include <optional>
#include <utility>

#include "lbp/bytes.hpp"
#include "lbp/preparse.hpp"

namespace i20::sim {

enum class FramingMode { Setup, Operate };

class Framer {
 public:
  using Clock = std::chrono::steady_clock;
  using Frame = lbp::CommandSplitter::Frame;

  struct Config {
    FramingMode mode = FramingMode::Setup;
    std::size_t capacity = 128;
    Clock::duration timeout{};  // command timeout (quiet line)
  };

  explicit Framer(Config config) : config_(config) {}

  void set_timeout(Clock::duration timeout) { config_.timeout = timeout; }
  Clock::duration timeout() const { return config_.timeout; }
  FramingMode mode() const { return config_.mode; }

  // One byte off the line at time t. Dropped if the buffer is full or while resyncing.
  void push(lbp::Byte byte, Clock::time_point t);
  // The next whole command, if one is ready (`rpc_table` gives RPC lengths).
  std::optional<Frame> next(lbp::ByteView rpc_table);
  // Applies the quiet-line rules at time t. In setup mode call it only when the device
  // has taken every ready frame (what is left is then a partial command).
  void expire(Clock::time_point t);
  // When expire() would next change something, if ever.
  std::optional<Clock::time_point> deadline() const;

  // Drops everything (reset, power loss).
  void clear();
  std::size_t pending() const;
  bool resyncing() const { return resyncing_; }

  // Events since the last call (each read clears it).
  bool take_overflow() { return std::exchange(overflow_, false); }
  bool take_timeout() { return std::exchange(timeout_, false); }
  std::size_t dropped_bytes() const { return dropped_; }

 private:
  bool quiet_since_last_byte(Clock::time_point t) const;
  void close_packet();
  void split_packet(const lbp::Bytes& packet, lbp::ByteView rpc_table);
  static bool still_fits(const Frame& frame, lbp::ByteView rpc_table);
  void drop_rest_of_packet(const Frame& frame);

  Config config_;
  lbp::CommandSplitter splitter_;  // setup mode
  lbp::Bytes packet_;              // operate mode: the packet being received
  std::deque<lbp::Bytes> closed_;  // operate mode: whole packets waiting to be split
  std::deque<Frame> ready_;        // operate mode: commands of the packet being executed
  std::size_t queued_bytes_ = 0;   // operate mode: bytes in closed_ and ready_
  std::optional<Clock::time_point> last_byte_;
  bool resyncing_ = false;
  bool overflow_ = false;
  bool timeout_ = false;
  std::size_t dropped_ = 0;
};

}  // namespace i20::sim
