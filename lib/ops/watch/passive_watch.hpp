// SPDX-License-Identifier: GPL-2.0-or-later
// `watch --passive` as a use case: the passive monitor (ops/watch/passive_monitor.hpp) sampled at
// an interval until --count samples, --duration or a stop signal, riding out a card that
// stops answering (said once, retried at the interval, said again when it answers). The
// views (plain lines, JSON lines, a CSV series) are the app's; they receive what happens
// through a PassiveWatchSink, as `watch` does through ops::MonitorSink.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

#include "ops/core/outcome.hpp"
#include "ops/watch/passive_monitor.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

struct PassiveRunOptions {
  std::chrono::milliseconds interval = timing::kWatchInterval;
  std::uint64_t count = 0;  // 0: no limit
  double duration_s = 0;    // 0: no limit
};

// Contact with the card lost (the first of a run of unanswered samples) or back.
struct PassiveLinkEvent {
  enum class Kind { Lost, Reconnected };
  std::chrono::system_clock::time_point when{};
  Kind kind = Kind::Lost;
  std::string text{};  // one line a person can act on
};
// "lost", "reconnected": the JSON spelling.
const char* to_string(PassiveLinkEvent::Kind kind);

struct PassiveWatchSummary {
  std::uint64_t samples = 0;
  std::uint64_t changes = 0;   // over every sample
  std::uint64_t missed = 0;    // samples the card did not answer
  std::uint64_t requests = 0;  // UDP requests sent, the card survey included
  double elapsed_s = 0;
  Outcome outcome = Outcome::Done;  // Interrupted after a stop signal (nothing was written)
};

class PassiveWatchSink {
 public:
  virtual ~PassiveWatchSink() = default;
  // Every sample read. Throwing ends the watch (a view whose reader has gone away).
  virtual void sample(const PassiveSample& s) = 0;
  virtual void link(const PassiveLinkEvent& e) = 0;
};

// Samples `monitor` every options.interval (the first at once, later ones on a fixed
// schedule that never catches up in bursts) and hands each sample or lost/regained contact
// to the sink. Ends on --count, --duration or a stop signal; an exception from the sink
// ends it too and passes through.
PassiveWatchSummary run_passive_monitor(PassiveMonitor& monitor, const PassiveRunOptions& options,
                                        PassiveWatchSink& sink);

}  // namespace i20::ops
