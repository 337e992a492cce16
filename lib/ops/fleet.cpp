#include "ops/fleet.hpp"

#include <map>
#include <thread>

namespace i20::ops {
namespace {

// Target indexes grouped by line, in order of first appearance.
std::vector<std::vector<std::size_t>> by_line(const std::vector<Endpoint>& targets) {
  std::vector<std::vector<std::size_t>> groups;
  std::map<std::string, std::size_t> group_of;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const auto [it, fresh] = group_of.try_emplace(targets[i].line_key, groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(i);
  }
  return groups;
}

}  // namespace

std::vector<TargetRun> run_fleet(const std::vector<Endpoint>& targets, const ApplyJob& job,
                                 const FleetActivity& activity) {
  std::vector<TargetRun> runs(targets.size());
  std::vector<std::thread> threads;
  for (const auto& line : by_line(targets)) {
    threads.emplace_back([&, line] {
      for (const std::size_t i : line) {
        Activity one;
        if (activity) one = [&activity, i](const std::string& s) { activity(i, s); };
        runs[i] = run_apply(targets[i], job, one);
        if (activity) activity(i, to_string(runs[i].outcome));
      }
    });
  }
  for (auto& t : threads) t.join();
  return runs;
}

}  // namespace i20::ops
