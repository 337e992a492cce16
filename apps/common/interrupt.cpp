// SPDX-License-Identifier: GPL-2.0-or-later
#include "interrupt.hpp"

#include <csignal>

namespace i20::app {
namespace {

// The one piece of process-wide state: a signal handler can reach nothing else.
std::atomic<bool> g_interrupted{false};

extern "C" void on_signal(int sig) {
  if (g_interrupted.exchange(true)) {
    std::signal(sig, SIG_DFL);  // second Ctrl-C: the user means it
    std::raise(sig);
  }
}

}  // namespace

const std::atomic<bool>& install_interrupt_handler() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  return g_interrupted;
}

bool interrupted() {
  return g_interrupted.load();
}

}  // namespace i20::app
