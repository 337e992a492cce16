// SPDX-License-Identifier: GPL-2.0-or-later
// The fleet's live status block on stderr: one line per target, redrawn in place while the
// worker threads run (for a terminal only).
#pragma once

#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ops/core/endpoint.hpp"
#include "ops/fleet.hpp"

namespace i20::cli {

class FleetProgress {
 public:
  FleetProgress(const std::vector<ops::Endpoint>& targets, bool enabled);
  ~FleetProgress();
  FleetProgress(const FleetProgress&) = delete;
  FleetProgress& operator=(const FleetProgress&) = delete;

  // What the fleet tells about each target (thread-safe); a no-op when disabled.
  ops::FleetActivity activity();
  void stop();

 private:
  void set(std::size_t index, const std::string& state);
  void loop();
  void draw();

  bool enabled_;
  std::vector<std::string> names_;
  std::vector<std::string> states_;
  std::size_t width_ = 0;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread drawer_;
  bool done_ = false;
  bool drawn_ = false;
};

}  // namespace i20::cli
