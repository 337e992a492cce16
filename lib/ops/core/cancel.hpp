// SPDX-License-Identifier: GPL-2.0-or-later
// Cancellation is an input of every use case: a request set from outside (the apps' SIGINT,
// SIGTERM and SIGHUP handler, a test, the soak) that the engine polls before the first
// write, between writes and between exchanges. The engine decides what a stop means for the
// card; the request only asks.
#pragma once

#include <atomic>
#include <functional>
#include <string>

namespace i20::ops {

// What a stop request sets. Only lock-free atomics, so a signal handler may set it
// (request() is async-signal-safe); the main flow reads it.
class StopRequest {
 public:
  // Async-signal-safe: stores and one fetch_add on lock-free atomics, nothing else.
  void request(int signal) noexcept {
    signal_.store(signal);
    count_.fetch_add(1);
    flag_.store(true);
  }
  bool requested() const noexcept { return flag_.load(); }
  int count() const noexcept { return count_.load(); }
  int signal() const noexcept { return signal_.load(); }  // the last one; 0 for none
  // The flag the device layer polls between exchanges.
  const std::atomic<bool>& flag() const noexcept { return flag_; }
  // Requests that arrived since the last call (and marks them acknowledged).
  int take_unacknowledged() noexcept { return count_.load() - acknowledged_.exchange(count_.load()); }

 private:
  static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free);
  std::atomic<bool> flag_{false};
  std::atomic<int> count_{0};
  std::atomic<int> signal_{0};
  std::atomic<int> acknowledged_{0};
};

class Cancel {
 public:
  // Told what the engine is doing when a request arrives while it cannot stop at once
  // (restoring a cell, leaving NV mode): the apps print "restoring NVKQP; the card settles
  // in a moment", so a second Ctrl-C is answered instead of ending the process.
  using Acknowledge = std::function<void(const std::string& doing)>;

  Cancel() = default;  // never cancelled
  explicit Cancel(const std::atomic<bool>& flag) : flag_(&flag) {}
  explicit Cancel(StopRequest& stop, Acknowledge acknowledge = {})
      : flag_(&stop.flag()), stop_(&stop), acknowledge_(std::move(acknowledge)) {}

  bool requested() const { return flag_ && flag_->load(); }
  // Throws device::Cancelled naming what was stopped.
  void check(const std::string& what) const;
  const std::atomic<bool>* flag() const { return flag_; }
  // At a point where the engine goes on despite the request (a restore, settling the card):
  // each request not acknowledged yet is answered once with what is being done.
  void acknowledge(const std::string& doing) const {
    if (stop_ && stop_->take_unacknowledged() > 0 && acknowledge_) acknowledge_(doing);
  }
  // "Ctrl-C" for SIGINT, "SIGTERM", "SIGHUP": what the reports name as the cause.
  std::string cause() const;

 private:
  const std::atomic<bool>* flag_ = nullptr;
  StopRequest* stop_ = nullptr;
  Acknowledge acknowledge_;
};

}  // namespace i20::ops
