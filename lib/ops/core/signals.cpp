// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/signals.hpp"

#include <algorithm>
#include <csignal>
#include <thread>

#include "device/suspend_hold.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {
namespace {

// The one piece of process-wide state: a signal handler can reach nothing else.
StopRequest g_stop;

extern "C" void on_stop_signal(int sig) {
  g_stop.request(sig);  // async-signal-safe; the main flow decides and answers
}

}  // namespace

StopRequest& install_stop_signals() {
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_handler = on_stop_signal;
    sigemptyset(&action.sa_mask);
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &action, nullptr);
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    sigaction(SIGPIPE, &ignore, nullptr);
    device::install_suspend_handler();  // Ctrl-Z waits for the card to leave NV/RPC memory mode
    return true;
  }();
  (void)installed;
  return g_stop;
}

bool stop_requested() {
  return g_stop.requested();
}

bool sleep_until(std::chrono::steady_clock::time_point t, const std::function<bool()>& done) {
  using Clock = std::chrono::steady_clock;
  while (Clock::now() < t) {
    if (done()) return false;
    std::this_thread::sleep_for(std::min<Clock::duration>(timing::kStopPollSlice, t - Clock::now()));
  }
  return !done();
}

}  // namespace i20::ops
