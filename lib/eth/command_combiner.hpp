// SPDX-License-Identifier: GPL-2.0-or-later
// Combining the links of one SSLBP passthrough port (passthrough_port.hpp). Links of
// different channels, used by several threads, each execute their own batch; batches that
// arrive at about the same time (within the gather window) are run as one execute() of the
// port, so that one DOIT serves every channel of the round. One thread leads: it waits for
// the others to join, runs the batches and hands each link its outcome. A second batch of a
// channel already taken waits for the next execute().
//
// This class only combines; what goes on the wire is the port's business (the `execute`
// function it is given).
#pragma once

#include <chrono>
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <span>
#include <vector>

#include "lbp/command.hpp"

namespace i20::eth {

// One channel's commands in an execute() (PassthroughPort::Batch).
struct ChannelBatch {
  unsigned channel = 0;
  std::span<const lbp::Command> commands{};
};

// What one channel's batch came to (PassthroughPort::execute). Not an ops::Outcome: that is
// what a whole command came to, and the exit code it maps to.
struct ChannelResult {
  unsigned channel = 0;
  std::vector<lbp::Bytes> replies{};  // one per command when no error
  // A link::LinkError (or subclass) whose completed() counts the commands of this
  // channel that got a reply; the other channels are unaffected.
  std::exception_ptr error{};
};

class CommandCombiner {
 public:
  // Runs the batches of several channels side by side (PassthroughPort::execute).
  using Execute = std::function<std::vector<ChannelResult>(std::span<const ChannelBatch>)>;

  // `gather_window`: how long a leader waits for the other attached links to join.
  CommandCombiner(Execute execute, std::chrono::microseconds gather_window);
  CommandCombiner(const CommandCombiner&) = delete;
  CommandCombiner& operator=(const CommandCombiner&) = delete;

  // Runs `batch` on `channel`, combined with other links' batches; throws what the
  // execute threw, or the channel's own error.
  std::vector<lbp::Bytes> execute(unsigned channel, std::span<const lbp::Command> batch);
  // A link that may execute: a leader waits for every attached link (up to the window).
  void attach() noexcept;
  void detach() noexcept;

 private:
  struct Request;

  void lead(std::unique_lock<std::mutex>& lock);

  Execute execute_;
  std::chrono::microseconds gather_window_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<Request*> pending_{};
  bool leading_ = false;
  unsigned attached_ = 0;
};

}  // namespace i20::eth
