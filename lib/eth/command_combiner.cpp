// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/command_combiner.hpp"

#include <cstdint>
#include <utility>

namespace i20::eth {

using Clock = std::chrono::steady_clock;

namespace {

std::uint8_t bit(unsigned channel) {
  return static_cast<std::uint8_t>(1u << channel);
}

}  // namespace

struct CommandCombiner::Request {
  unsigned channel = 0;
  std::span<const lbp::Command> batch{};
  ChannelResult outcome{};
  std::exception_ptr port_error{};
  bool done = false;
};

CommandCombiner::CommandCombiner(Execute execute, std::chrono::microseconds gather_window)
    : execute_(std::move(execute)), gather_window_(gather_window) {}

void CommandCombiner::attach() noexcept {
  std::lock_guard lock(mutex_);
  ++attached_;
}

void CommandCombiner::detach() noexcept {
  {
    std::lock_guard lock(mutex_);
    --attached_;
  }
  changed_.notify_all();  // a leader waiting for this link need not wait any more
}

std::vector<lbp::Bytes> CommandCombiner::execute(unsigned channel, std::span<const lbp::Command> batch) {
  Request request{.channel = channel, .batch = batch};
  std::unique_lock lock(mutex_);
  pending_.push_back(&request);
  changed_.notify_all();
  while (!request.done) {
    if (!leading_)
      lead(lock);
    else
      changed_.wait(lock, [&] { return request.done || !leading_; });
  }
  if (request.port_error) std::rethrow_exception(request.port_error);
  if (request.outcome.error) std::rethrow_exception(request.outcome.error);
  return std::move(request.outcome.replies);
}

void CommandCombiner::lead(std::unique_lock<std::mutex>& lock) {
  leading_ = true;
  // Give the other links a moment to join: one DOIT then serves them all.
  changed_.wait_until(lock, Clock::now() + gather_window_, [&] { return pending_.size() >= attached_; });
  std::vector<Request*> taken, later;
  std::uint8_t seen = 0;
  for (Request* r : pending_) {
    if (seen & bit(r->channel)) {
      later.push_back(r);  // a second batch of a channel waits for the next round
      continue;
    }
    seen |= bit(r->channel);
    taken.push_back(r);
  }
  pending_ = std::move(later);
  lock.unlock();
  std::vector<ChannelBatch> batches;
  for (const Request* r : taken) batches.push_back(ChannelBatch{.channel = r->channel, .commands = r->batch});
  try {
    auto outcomes = execute_(batches);
    for (std::size_t i = 0; i < taken.size(); ++i) taken[i]->outcome = std::move(outcomes[i]);
  } catch (...) {
    for (Request* r : taken) r->port_error = std::current_exception();
  }
  lock.lock();
  for (Request* r : taken) r->done = true;
  leading_ = false;
  changed_.notify_all();
}

}  // namespace i20::eth
