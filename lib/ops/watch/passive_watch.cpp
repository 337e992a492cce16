// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/watch/passive_watch.hpp"

#include <algorithm>
#include <functional>
#include <thread>

#include "ops/core/errors.hpp"
#include "ops/core/signals.hpp"

namespace i20::ops {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

const char* to_string(PassiveLinkEvent::Kind kind) {
  switch (kind) {
    case PassiveLinkEvent::Kind::Lost: return "lost";
    case PassiveLinkEvent::Kind::Reconnected: return "reconnected";
  }
  return "?";
}

PassiveWatchSummary run_passive_monitor(PassiveMonitor& monitor, const PassiveRunOptions& options,
                                        PassiveWatchSink& sink) {
  PassiveWatchSummary summary;
  const auto start = Clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  const std::function<bool()> done = [&] {
    return stop_requested() || (options.count && summary.samples >= options.count) ||
           (options.duration_s > 0 && elapsed() >= options.duration_s);
  };
  bool lost = false;
  auto next = Clock::now();
  while (!done()) {
    if (summary.samples > 0 || lost)
      if (!sleep_until(next, done)) break;
    next += options.interval;
    if (next < Clock::now()) next = Clock::now();  // late: the next sample at once, no burst after
    PassiveSample s;
    try {
      s = monitor.sample();
    } catch (const LinkError& e) {
      ++summary.missed;
      if (!lost) {
        lost = true;
        sink.link({std::chrono::system_clock::now(), PassiveLinkEvent::Kind::Lost,
                   std::string("no reply from the card: ") + e.what() + "; still trying"});
      }
      continue;
    }
    if (lost) {
      lost = false;
      sink.link({s.when, PassiveLinkEvent::Kind::Reconnected, "the card answers again"});
    }
    ++summary.samples;
    summary.changes += s.changes.size();
    sink.sample(s);
  }
  summary.elapsed_s = elapsed();
  summary.requests = monitor.reader().requests_sent();
  summary.outcome = stop_requested() ? Outcome::Interrupted : Outcome::Done;  // the card left as it was
  return summary;
}

}  // namespace i20::ops
