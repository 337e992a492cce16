// SPDX-License-Identifier: GPL-2.0-or-later
// The end of the operation that runs on this thread, for the waits below ops (issue 40).
//
// ops gives every command one deadline, counted from the moment it starts opening its card,
// and a settle budget after it for the way back (restores, leaving NV access and RPC memory
// mode). A wait for one reply can be longer than what is left (a UDP packet that may not be
// resent waits over all its attempts, up to seconds), and a command makes many exchanges,
// so the bound must reach each wait, not only each exchange ops starts. The links sit below
// ops and are shared (the channels of one Ethernet port pack their batches into one packet)
// so the bound travels with the thread that runs the operation, not with a link: ops opens a
// WaitBound around its work, and a transport asks remaining() before it sends and while it
// waits. Scoped: the bound it replaced comes back when it ends, so a nested scope (the
// way back inside an operation) can lift or extend it.
//
// The one state of its kind in the code: a per-thread value, set and restored only by this
// RAII scope.
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace i20::link {

class WaitBound {
 public:
  using Clock = std::chrono::steady_clock;
  // Waits on this thread end by `until`; nullopt lifts any bound for the scope (a fence
  // after a lost write, which must run its own bounded course whatever the operation's).
  explicit WaitBound(std::optional<Clock::time_point> until);
  ~WaitBound();
  WaitBound(const WaitBound&) = delete;
  WaitBound& operator=(const WaitBound&) = delete;

  // The bound in force on this thread, if any.
  static std::optional<Clock::time_point> current();
  // What is left of it (zero once it has passed), or nullopt when none is in force.
  static std::optional<Clock::duration> remaining();
  // `wait` cut to what is left of the bound.
  static Clock::duration cap(Clock::duration wait);
  // True when a bound is in force and has passed: nothing more should be sent.
  static bool expired();
  // Throws OutOfTime, naming `destination`, when the bound has passed: a packet for it is
  // not to be sent.
  static void require_time_left(const std::string& destination);

 private:
  std::optional<Clock::time_point> previous_;
};

}  // namespace i20::link
