// SPDX-License-Identifier: GPL-2.0-or-later
// A program running in the background while the test drives the simulator: `i20 watch`
// has to be watching while the world changes, which harness.hpp's run() (run to
// completion) cannot express. Output is collected whenever the test waits for it.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "harness.hpp"

namespace i20::test {

class Spawned {
 public:
  Spawned(const std::string& name, const std::vector<std::string>& args);
  ~Spawned();  // kills the program if the test did not finish() it
  Spawned(const Spawned&) = delete;
  Spawned& operator=(const Spawned&) = delete;

  // Position of `needle` in stdout at or after `from`, waiting up to `timeout` for it;
  // std::string::npos if it did not appear (or the program ended without it).
  std::size_t wait_for(const std::string& needle, std::size_t from = 0,
                       std::chrono::milliseconds timeout = std::chrono::seconds(15));
  // Sends `sig` (SIGINT: what Ctrl-C sends), collects the rest of the output and the exit code.
  Result finish(int sig, std::chrono::milliseconds timeout = std::chrono::seconds(15));
  // Collects output for up to `wait`; false once the program has closed its output (ended).
  bool running(std::chrono::milliseconds wait) { return pump(static_cast<int>(wait.count())); }
  const std::string& out() const { return out_; }
  const std::string& err() const { return err_; }

 private:
  // Reads what is available within `timeout_ms`. False once both pipes are closed.
  bool pump(int timeout_ms);

  int pid_ = -1;
  int out_fd_ = -1;
  int err_fd_ = -1;
  std::string out_;
  std::string err_;
};

}  // namespace i20::test
