// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 watch` as a use case: samples FAULT, STATUS, FAULTMASK, bus voltage and temperature
// at an interval, turns every change into a timestamped event that says what it means and
// what to check, survives a card that resets or an adapter that is unplugged (says so and
// reconnects), and on Ethernet goes on in SSLBP normal mode after a first register read.
// The views (a redrawn screen, plain lines, JSON lines, a CSV series) are the apps'; they
// receive what happens through a MonitorSink.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ops/faults.hpp"
#include "ops/core/outcome.hpp"
#include "ops/core/session.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

using WallClock = std::chrono::system_clock;

struct MonitorEvent {
  enum class Kind {
    FaultSet,
    FaultCleared,
    StatusSet,
    StatusCleared,
    Mask,
    Output,
    Lost,
    Reconnected,
    Restarted,
    Mode,  // the source changed (Ethernet: from register reads to SSLBP normal mode)
  };
  WallClock::time_point when;
  Kind kind = Kind::FaultSet;
  std::string text;  // one line a person can act on
  std::optional<unsigned> bit;
  std::string name;
  double elapsed_s = 0;  // since the monitor started
};
// "fault_set", "lost", ...: the JSON spelling.
const char* to_string(MonitorEvent::Kind kind);

struct MonitorSample {
  WallClock::time_point when;
  double elapsed_s = 0;
  FaultReadings r;
};

struct MonitorSummary {
  std::uint64_t samples = 0;
  double elapsed_s = 0;
  std::uint64_t fault_changes = 0;
  std::uint64_t reconnects = 0;
  bool connected = true;
};

struct MonitorOptions {
  std::chrono::milliseconds interval = timing::kWatchInterval;
  std::uint64_t count = 0;  // 0: no limit
  double duration_s = 0;    // 0: no limit
  bool registers = false;   // Ethernet: stay on register reads instead of SSLBP normal mode
};

class MonitorSink {
 public:
  virtual ~MonitorSink() = default;
  virtual void start(const std::string& target, const MonitorOptions& options) = 0;
  // A sample, the one before it (none for the first), and the events it brought.
  virtual void sample(const MonitorSample& s, const FaultReadings* previous,
                      const std::vector<MonitorEvent>& events) = 0;
  // Events that come without a sample (lost contact).
  virtual void event(const MonitorEvent& e) = 0;
  virtual void finish(const MonitorSummary& summary) = 0;
};

// Runs until --count samples, --duration, or a stop signal. The first read is always a
// register read, so latched faults are shown as they are; a card that cannot be read at
// all then is an error (thrown), not a wait. Returns Done, or Interrupted after a stop
// signal (the card left as it was).
Outcome run_monitor(Session& session, const MonitorOptions& options, MonitorSink& sink);

}  // namespace i20::ops
