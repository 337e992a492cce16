#include "fleet.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <iostream>
#include <map>
#include <mutex>
#include <thread>

#include "profile_render.hpp"

namespace i20::cli {
namespace {

// The status line of every target, written by the worker threads, drawn by one thread.
class Progress {
 public:
  Progress(const std::vector<TargetSpec>& targets, bool enabled) : enabled_(enabled) {
    for (const auto& t : targets) {
      names_.push_back(t.text);
      width_ = std::max(width_, t.text.size());
    }
    states_.assign(targets.size(), "waiting");
  }

  void set(std::size_t index, const std::string& state) {
    std::lock_guard lock(mutex_);
    states_[index] = state;
  }

  void start() {
    if (!enabled_) return;
    drawer_ = std::thread([this] { loop(); });
  }

  void stop() {
    if (!enabled_) return;
    {
      std::lock_guard lock(mutex_);
      done_ = true;
    }
    wake_.notify_all();
    drawer_.join();
  }

 private:
  void loop() {
    std::unique_lock lock(mutex_);
    while (true) {
      draw();
      if (done_) return;
      wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return done_; });
    }
  }

  // Moves back over the previous frame and overwrites it line by line (ANSI: cursor up,
  // clear line), so the block stays in place while the targets progress.
  void draw() {
    if (drawn_) std::cerr << "\033[" << names_.size() << "A";
    for (std::size_t i = 0; i < names_.size(); ++i)
      std::cerr << "\r\033[K  " << names_[i] << std::string(width_ - names_[i].size() + 2, ' ') << states_[i]
                << "\n";
    std::cerr << std::flush;
    drawn_ = true;
  }

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

// Target indexes grouped by line, in order of first appearance.
std::vector<std::vector<std::size_t>> by_line(const std::vector<TargetSpec>& targets) {
  std::vector<std::vector<std::size_t>> groups;
  std::map<std::string, std::size_t> group_of;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const auto [it, fresh] = group_of.try_emplace(targets[i].link_key, groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(i);
  }
  return groups;
}

}  // namespace

std::vector<TargetRun> run_fleet(const std::vector<TargetSpec>& targets, const ApplyJob& job,
                                 const FleetOptions& options) {
  std::vector<TargetRun> runs(targets.size());
  Progress progress(targets, options.progress);
  progress.start();
  std::vector<std::thread> threads;
  for (const auto& line : by_line(targets)) {
    threads.emplace_back([&, line] {
      for (const std::size_t i : line) {
        runs[i] = run_apply(targets[i], job, [&progress, i](const std::string& s) { progress.set(i, s); });
        progress.set(i, render::outcome_name(runs[i]));
      }
    });
  }
  for (auto& t : threads) t.join();
  progress.stop();
  return runs;
}

}  // namespace i20::cli
