// SPDX-License-Identifier: GPL-2.0-or-later
#include "fleet_progress.hpp"

#include <algorithm>
#include <chrono>
#include <iostream>

namespace i20::cli {

FleetProgress::FleetProgress(const std::vector<ops::Endpoint>& targets, bool enabled) : enabled_(enabled) {
  for (const auto& t : targets) {
    names_.push_back(t.text);
    width_ = std::max(width_, t.text.size());
  }
  states_.assign(targets.size(), "waiting");
  if (enabled_) drawer_ = std::thread([this] { loop(); });
}

FleetProgress::~FleetProgress() {
  stop();
}

ops::FleetActivity FleetProgress::activity() {
  if (!enabled_) return {};
  return [this](std::size_t index, const std::string& state) { set(index, state); };
}

void FleetProgress::set(std::size_t index, const std::string& state) {
  std::lock_guard lock(mutex_);
  states_[index] = state;
}

void FleetProgress::stop() {
  if (!drawer_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    done_ = true;
  }
  wake_.notify_all();
  drawer_.join();
}

void FleetProgress::loop() {
  std::unique_lock lock(mutex_);
  while (true) {
    draw();
    if (done_) return;
    wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return done_; });
  }
}

// Moves back over the previous frame and overwrites it line by line (ANSI: cursor up,
// clear line), so the block stays in place while the targets progress.
void FleetProgress::draw() {
  if (drawn_) std::cerr << "\033[" << names_.size() << "A";
  for (std::size_t i = 0; i < names_.size(); ++i)
    std::cerr << "\r\033[K  " << names_[i] << std::string(width_ - names_[i].size() + 2, ' ') << states_[i] << "\n";
  std::cerr << std::flush;
  drawn_ = true;
}

}  // namespace i20::cli
