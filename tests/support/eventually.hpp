// SPDX-License-Identifier: GPL-2.0-or-later
// The tests' one way to wait for what another thread or process does (a state, a counter, a
// line, bytes in a queue): ask until it holds, within a generous bound. Not a fixed sleep, so a
// loaded machine slows a test but fails none, and an event that never comes fails it loudly
// (assert on the answer) instead of hanging it.
#pragma once

#include <chrono>
#include <thread>

namespace i20::test {

// Waits until `done()` holds, for at most `limit`, asking every `poll` (a poll interval, not
// a wait for anything to happen). Returns the last answer; assert on it.
template <class Done>
bool eventually(Done&& done, std::chrono::milliseconds limit = std::chrono::milliseconds(5000),
                std::chrono::milliseconds poll = std::chrono::milliseconds(2)) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= deadline) return done();
    std::this_thread::sleep_for(poll);
  }
  return true;
}

}  // namespace i20::test
