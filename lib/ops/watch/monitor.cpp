// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/watch/monitor.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <thread>

#include "faults/bit_diff.hpp"
#include "faults/fault_mask.hpp"
#include "lbp/bytes.hpp"
#include "ops/core/errors.hpp"
#include "ops/core/signals.hpp"
#include "ops/watch/live_readings.hpp"
#include "ops/watch/live_source.hpp"

namespace i20::ops {
namespace {

namespace F = i20::faults;
using Clock = std::chrono::steady_clock;
using Kind = MonitorEvent::Kind;

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

// ------------------------------------------------------------------ events from two samples
MonitorEvent bit_event(WallClock::time_point when, Kind kind, const F::DecodedBit& b) {
  MonitorEvent e{when, kind, {}, b.bit, b.label()};
  const bool fault = b.reg == F::Register::Fault;
  const bool set = kind == Kind::FaultSet || kind == Kind::StatusSet;
  e.text = std::string(fault ? "FAULT " : "STATUS ") + (set ? "set: " : "cleared: ") + b.label() + " (bit " +
           std::to_string(b.bit) + ")";
  if (!set) return e;
  std::string meaning = b.meaning();
  if (!meaning.empty() && meaning.back() == '.') meaning.pop_back();  // "...; check: ..." follows
  e.text += ": " + meaning;
  // A fault that just rose needs the first thing to check; STATUS bits explain themselves.
  if (fault && b.info && !b.info->checks.empty()) e.text += "; check: " + b.info->checks.front();
  return e;
}

void add_bits(std::vector<MonitorEvent>& out, WallClock::time_point when, const F::BitChanges& c, Kind rose,
              Kind fell) {
  for (const auto& b : c.rose) out.push_back(bit_event(when, rose, b));
  for (const auto& b : c.fell) out.push_back(bit_event(when, fell, b));
}

std::vector<MonitorEvent> changes(const FaultReadings& before, const FaultReadings& after,
                                  WallClock::time_point when) {
  std::vector<MonitorEvent> out;
  add_bits(out, when, F::diff(F::Register::Fault, before.fault, after.fault), Kind::FaultSet,
           Kind::FaultCleared);
  if (output_on(before) != output_on(after))
    out.push_back({when,
                   Kind::Output,
                   output_on(after)
                       ? "fault output ON: no unmasked fault, the drive may run"
                       : "fault output OFF: a non-masked fault stopped motor drive and the current loop",
                   {},
                   {}});
  add_bits(out, when, F::diff(F::Register::Status, before.status, after.status), Kind::StatusSet,
           Kind::StatusCleared);
  if (before.faultmask != after.faultmask && after.faultmask)
    out.push_back({when,
                   Kind::Mask,
                   "FAULTMASK " + (before.faultmask ? lbp::hex_value(*before.faultmask, 4) : "?") + " -> " +
                       lbp::hex_value(*after.faultmask, 4),
                   {},
                   {}});
  return out;
}

// STATUS bits whose knowledge-base escalation starts to hold (BRAKESTATUS while the bus sits
// above BRAKEONV): a warning that says what will happen, once, when it begins.
std::vector<MonitorEvent> warning_events(const FaultReadings* before, const FaultReadings& after,
                                         WallClock::time_point when) {
  std::vector<MonitorEvent> out;
  const auto was = before ? live_status_report(*before) : F::Report{};
  for (const auto& line : live_status_report(after).lines) {
    if (!line.escalated) continue;
    const bool already = std::any_of(was.lines.begin(), was.lines.end(), [&](const F::ReportLine& w) {
      return w.bit == line.bit && w.escalated;
    });
    if (already) continue;
    out.push_back({when, Kind::StatusSet,
                   "WARNING: " + bit_label(line) + ": " + line.meaning + " (" + line.evidence + ")", line.bit,
                   line.name});
  }
  return out;
}

// ------------------------------------------------------------------ the loop
class Monitor {
 public:
  Monitor(Session& session, const MonitorOptions& o, MonitorSink& sink)
      : session_(session), o_(o), sink_(sink), source_(make_live_source(session, LiveMode::Registers)) {}

  Outcome run();

 private:
  bool done() const;
  bool sleep_until(Clock::time_point t) const;
  FaultReadings read() { return source_->read(); }
  void record(const FaultReadings& r, std::vector<MonitorEvent> events);
  void sample_once();
  void lose(const std::string& why);
  std::vector<MonitorEvent> restart_events(const FaultReadings& r);
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  std::string target() { return source_->describe(); }
  void switch_to_normal_mode(std::vector<MonitorEvent>& events);

  Session& session_;
  const MonitorOptions& o_;
  MonitorSink& sink_;
  Clock::time_point start_;
  std::optional<FaultReadings> previous_;
  std::optional<Clock::time_point> lost_at_;  // set while the card cannot be read
  std::string where_;
  MonitorSummary summary_;
  std::unique_ptr<LiveSource> source_;
};

bool Monitor::done() const {
  if (session_.stop_requested()) return true;
  if (o_.count && summary_.samples >= o_.count) return true;
  return o_.duration_s > 0 && elapsed() >= o_.duration_s;
}

// Sleeps in slices so Ctrl-C and --duration end the watch promptly. False: stop now.
bool Monitor::sleep_until(Clock::time_point t) const {
  return ops::sleep_until(t, [this] { return done(); });
}

std::vector<MonitorEvent> Monitor::restart_events(const FaultReadings& r) {
  std::vector<MonitorEvent> out;
  if (!previous_) return out;
  const auto rose = static_cast<std::uint16_t>(r.status & ~previous_->status & F::kResetCauseBits);
  if (rose == 0) return out;
  out.push_back({WallClock::now(),
                 Kind::Restarted,
                 "8I20 restarted (" + bit_names(F::Register::Status, rose) +
                     " rose): working values are back to their NV values; reconnecting to re-identify it",
                 {},
                 {}});
  source_->reconnect();  // the next read opens the link again and re-reads SWREVISION
  return out;
}

void Monitor::record(const FaultReadings& r, std::vector<MonitorEvent> events) {
  MonitorSample s{WallClock::now(), elapsed(), r};
  const auto when = s.when;
  if (previous_) {
    auto diffs = changes(*previous_, r, when);
    events.insert(events.end(), diffs.begin(), diffs.end());
    if (previous_->fault != r.fault) ++summary_.fault_changes;
  }
  auto restarted = restart_events(r);
  events.insert(events.end(), restarted.begin(), restarted.end());
  auto warnings = warning_events(previous_ ? &*previous_ : nullptr, r, when);
  events.insert(events.end(), warnings.begin(), warnings.end());
  for (auto& e : events) e.elapsed_s = s.elapsed_s;
  ++summary_.samples;
  sink_.sample(s, previous_ ? &*previous_ : nullptr, events);
  previous_ = r;
}

void Monitor::lose(const std::string& why) {
  lost_at_ = Clock::now();
  summary_.connected = false;
  MonitorEvent e{WallClock::now(),
                 Kind::Lost,
                 "lost contact with the 8I20 on " + where_ + ": " + why + "; retrying every " +
                     seconds_text(std::chrono::duration<double>(retry_interval(o_.interval)).count()) +
                     " (Ctrl-C stops)",
                 {},
                 {}};
  e.elapsed_s = elapsed();
  sink_.event(e);
  source_->reconnect();  // drop the link: the port may have gone away with the adapter
}

void Monitor::sample_once() {
  std::vector<MonitorEvent> events;
  std::optional<FaultReadings> r;
  try {
    r = read();
    if (lost_at_) {
      const double away = std::chrono::duration<double>(Clock::now() - *lost_at_).count();
      events.push_back({WallClock::now(),
                        Kind::Reconnected,
                        "reconnected to the 8I20 on " + target() + " after " + seconds_text(away),
                        {},
                        {}});
      ++summary_.reconnects;
      lost_at_.reset();
      summary_.connected = true;
    }
  } catch (const Cancelled&) {
    return;  // a stop signal during a read: done() ends the loop
  } catch (const UsageError&) {
    throw;
  } catch (const Error& e) {
    if (lost_at_) {
      source_->reconnect();  // still away: try a fresh open next time
      return;
    }
    lose(e.what());
    return;
  }
  // Outside the try: the sink's own failure (its reader gone, a full disk) is not the card's,
  // and ends the monitor instead of reading as lost contact.
  record(*r, std::move(events));
}

// SSLBP's normal start clears faults and enables the current loop (manual, 8I20 DEVICE
// SPECIFIC SETUP): only after the latched faults were reported, and saying so.
void Monitor::switch_to_normal_mode(std::vector<MonitorEvent>& events) {
  if (o_.registers || !is_eth_target(session_)) return;
  source_->reconnect();  // close the setup-mode passthrough before the port is re-moded
  source_ = make_live_source(session_, LiveMode::NormalModeOnEthernet);
  events.push_back({WallClock::now(),
                    Kind::Mode,
                    "switching to SSLBP normal mode for the live view: its start CLEARS the latched faults "
                    "above and enables the current loop (QSETPOINT stays 0); use --registers to keep reading "
                    "registers",
                    {},
                    {}});
}

Outcome Monitor::run() {
  start_ = Clock::now();
  const FaultReadings first = read();  // a card that cannot be read at all is an error, not a wait
  where_ = target();
  sink_.start(where_, o_);
  std::vector<MonitorEvent> initial;
  for (const auto& b : F::decode_fault(first.fault).bits)
    initial.push_back(bit_event(WallClock::now(), Kind::FaultSet, b));
  switch_to_normal_mode(initial);
  record(first, std::move(initial));
  auto next = start_ + o_.interval;
  while (!done()) {
    if (!sleep_until(next)) break;
    sample_once();
    const auto step = lost_at_ ? retry_interval(o_.interval) : o_.interval;
    next += step;
    if (next < Clock::now()) next = Clock::now() + step;  // a slow read skips ticks, never bunches them
  }
  summary_.elapsed_s = elapsed();
  sink_.finish(summary_);
  return session_.stop_requested() ? Outcome::Interrupted : Outcome::Done;  // the card left as it was
}

}  // namespace

const char* to_string(MonitorEvent::Kind k) {
  switch (k) {
    case Kind::FaultSet: return "fault_set";
    case Kind::FaultCleared: return "fault_cleared";
    case Kind::StatusSet: return "status_set";
    case Kind::StatusCleared: return "status_cleared";
    case Kind::Mask: return "faultmask";
    case Kind::Output: return "fault_output";
    case Kind::Lost: return "lost";
    case Kind::Reconnected: return "reconnected";
    case Kind::Restarted: return "restarted";
    case Kind::Mode: return "mode";
  }
  return "";
}

Outcome run_monitor(Session& session, const MonitorOptions& options, MonitorSink& sink) {
  return Monitor(session, options, sink).run();
}

}  // namespace i20::ops
