// SPDX-License-Identifier: GPL-2.0-or-later
// Another host running the machine, for tests and demonstrations: it drives the virtual
// card's 8I20s the way LinuxCNC's hm2_eth does, through the card's own LBP16 path, so a
// client sees what it would see beside a running machine: the space 6 UDP counters move
// with packets that are not its own, COMMAND is busy during the host's DOITs, and a stop
// by anyone else makes the host's DOITs fail (its 8I20s' watchdogs bite 40 ms later).
//
// Sequence (8I20 manual, "NORMAL MODE OPERATION"): stop, normal start of its channels,
// then one packet per period: read COMMAND, DATA, INTERFACE0/1 of each channel, write
// INTERFACE0 (0, no current, unless HostOptions::interface0 says otherwise), write
// COMMAND = DOIT. stop() sends a stop, as LinuxCNC does when it exits.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "ethsim/virtual_board.hpp"

namespace i20::ethsim {

struct HostOptions {
  unsigned port = 0;  // SSERIAL port it runs
  // Channels it starts. 0: every 8I20 of the port, as LinuxCNC starts every remote it
  // finds (BoardServer::start_host resolves it; a SimulatedHost on its own takes channel 0).
  std::uint8_t mask = 0;
  Clock::duration period = std::chrono::milliseconds(1);  // LinuxCNC's default servo period
  // What the host writes to a channel's INTERFACE0 each cycle: the 8I20's ANGLE in bits
  // 0-15 and QSETPOINT in bits 16-31 (8I20 manual, 8I20 SPECIFIC INTERFACE REGISTER 0),
  // e.g. a commutating servo loop in a test. Unset: 0, no current.
  std::function<std::uint32_t(unsigned channel)> interface0{};
};

struct HostStats {
  std::uint64_t packets = 0;
  std::uint64_t cycles = 0;         // DOITs issued
  std::uint64_t failed_cycles = 0;  // DOITs whose DATA named a channel (the port was taken away)
  std::uint64_t late_cycles = 0;    // COMMAND still busy at the next cycle
  // The longest time between two DOITs: past the 8I20's 40 ms watchdog, this process (the
  // stand-in host) was starved, and a watchdog fault is the host's, not a client's doing.
  Clock::duration longest_gap{};
};

class SimulatedHost {
 public:
  // Nothing is sent until the first run_until().
  explicit SimulatedHost(HostOptions options = {});

  // Sends what is due up to `now` (state changes, one cycle per elapsed period; a host that
  // fell behind does not burst to catch up).
  void run_until(VirtualBoard& board, Clock::time_point now);
  // The host's exit: a stop of its port.
  void stop(VirtualBoard& board, Clock::time_point now);

  Clock::time_point next_due() const { return next_; }
  bool running() const { return state_ == State::Running; }
  const HostOptions& options() const { return options_; }
  const HostStats& stats() const { return stats_; }
  // "normal mode on SSERIAL port 0 ch 0, every 1 ms, 1234 DOITs (0 failed)".
  std::string describe() const;

 private:
  enum class State { Stopping, Starting, Running, Stopped };
  std::vector<lbp::Bytes> send(VirtualBoard& board, const std::vector<lbp::lbp16::Command>& packet,
                               Clock::time_point now);
  std::uint32_t command_register(VirtualBoard& board, Clock::time_point now);

  HostOptions options_;
  State state_ = State::Stopping;
  bool start_issued_ = false;
  Clock::time_point next_{};
  std::optional<Clock::time_point> last_doit_;
  HostStats stats_;
};

}  // namespace i20::ethsim
