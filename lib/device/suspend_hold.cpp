// SPDX-License-Identifier: GPL-2.0-or-later
#include "device/suspend_hold.hpp"

#include <atomic>
#include <csignal>

namespace i20::device {
namespace {

// Process-wide by nature: a signal handler can reach nothing else. Lock-free atomics only
// (async-signal-safe).
std::atomic<int> g_holds{0};
std::atomic<bool> g_suspend_pending{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);

// Stops the process as Ctrl-Z would. SIGSTOP rather than SIGTSTP's default action: the
// kernel discards a default-action SIGTSTP in an orphaned process group (a tool started by
// a script whose shell has gone), and Ctrl-Z must not be lost only because it was held.
// Execution continues here on SIGCONT, with this handler still in place.
void stop_now() {
  raise(SIGSTOP);
}

extern "C" void on_suspend_signal(int) {
  if (g_holds.load() > 0)
    g_suspend_pending = true;  // the hold's end stops the process, the card settled
  else
    stop_now();
}

}  // namespace

void install_suspend_handler() {
  struct sigaction action {};
  action.sa_handler = on_suspend_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGTSTP, &action, nullptr);
}

SuspendHold::SuspendHold() {
  ++g_holds;
}

SuspendHold::~SuspendHold() {
  if (--g_holds == 0 && g_suspend_pending.exchange(false)) raise(SIGTSTP);
}

}  // namespace i20::device
