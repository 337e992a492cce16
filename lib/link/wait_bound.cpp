// SPDX-License-Identifier: GPL-2.0-or-later
#include "link/wait_bound.hpp"

#include <algorithm>

#include "link/link.hpp"

namespace i20::link {
namespace {

thread_local std::optional<WaitBound::Clock::time_point> bound_on_this_thread;

}  // namespace

WaitBound::WaitBound(std::optional<Clock::time_point> until) : previous_(bound_on_this_thread) {
  bound_on_this_thread = until;
}

WaitBound::~WaitBound() {
  bound_on_this_thread = previous_;
}

std::optional<WaitBound::Clock::time_point> WaitBound::current() {
  return bound_on_this_thread;
}

std::optional<WaitBound::Clock::duration> WaitBound::remaining() {
  if (!bound_on_this_thread) return std::nullopt;
  return std::max(Clock::duration::zero(), *bound_on_this_thread - Clock::now());
}

WaitBound::Clock::duration WaitBound::cap(Clock::duration wait) {
  const auto left = remaining();
  return left ? std::min(wait, *left) : wait;
}

bool WaitBound::expired() {
  const auto left = remaining();
  return left && *left == Clock::duration::zero();
}

void WaitBound::require_time_left(const std::string& destination) {
  if (expired()) throw OutOfTime("the command's time was up before a packet to " + destination + " was sent");
}

}  // namespace i20::link
