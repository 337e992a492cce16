// SPDX-License-Identifier: GPL-2.0-or-later
// Cancellation is an input of every use case: a flag set from outside (a SIGINT handler in
// the apps, a test) that the engine polls before the first write, between writes and
// between exchanges. The engine decides what a stop means for the card; the flag only asks.
#pragma once

#include <atomic>
#include <string>

namespace i20::ops {

class Cancel {
 public:
  Cancel() = default;  // never cancelled
  explicit Cancel(const std::atomic<bool>& flag) : flag_(&flag) {}

  bool requested() const { return flag_ && flag_->load(); }
  // Throws device::Cancelled naming what was stopped.
  void check(const std::string& what) const;
  const std::atomic<bool>* flag() const { return flag_; }

 private:
  const std::atomic<bool>* flag_ = nullptr;
};

// How often a step is tried again when the line loses or garbles a reply: the one retry
// policy of the toolkit. Reads are repeated as they are (they change nothing); writes are
// repeated only after a read-back shows the card does not hold the value yet.
struct RetryPolicy {
  unsigned attempts = 3;
};

}  // namespace i20::ops
