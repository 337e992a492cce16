// SPDX-License-Identifier: GPL-2.0-or-later
#include "interrupt.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>

namespace i20::app {
namespace {

// The one piece of process-wide state: a signal handler can reach nothing else.
ops::StopRequest g_stop;
// Set once, before the handlers are installed; read by the main flow only.
std::atomic<const char*> g_program{"i20"};

extern "C" void on_signal(int sig) {
  g_stop.request(sig);  // async-signal-safe; the main flow decides and answers
}

void acknowledge(const std::string& doing) {
  // One write(2) of a line built by the main flow (not by the handler): it still reaches
  // a terminal when std::cerr has failed before.
  const std::string line = std::string(g_program.load()) + ": " + doing + "; the card settles in a moment\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, line.data(), line.size());
}

}  // namespace

ops::Cancel install_interrupt_handler(const char* program) {
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    for (const int sig : {SIGINT, SIGTERM, SIGHUP}) sigaction(sig, &action, nullptr);
    struct sigaction ignore {};
    ignore.sa_handler = SIG_IGN;
    sigemptyset(&ignore.sa_mask);
    sigaction(SIGPIPE, &ignore, nullptr);
    return true;
  }();
  (void)installed;
  if (program) g_program.store(program);
  return ops::Cancel(g_stop, acknowledge);
}

bool interrupted() {
  return g_stop.requested();
}

bool output_failed(const char* program) {
  std::cout.flush();
  std::cerr.flush();
  if (std::cout.good() && std::cerr.good() && std::fflush(stdout) == 0 && !std::ferror(stdout)) return false;
  const std::string line = std::string(program) +
                           ": note: standard output or error was closed before the report was complete "
                           "(the card was settled first; the exit code is the command's outcome)\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, line.data(), line.size());
  return true;
}

}  // namespace i20::app
