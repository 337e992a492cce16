// SPDX-License-Identifier: GPL-2.0-or-later
// i20 watch: a live view of bus voltage, card temperature, brake, STATUS and FAULT.
//
// Made for standing at the machine while the axis runs: every change of FAULT, STATUS or
// FAULTMASK becomes a timestamped event that says what the bit means and what to check,
// and a card that resets or an adapter that is unplugged does not end the watch: it says
// so and reconnects. Three views share one loop: a redrawn screen on a terminal, plain
// lines for pipes and files (--plain), and JSON lines (--json); --log adds a CSV series.
#include <sys/ioctl.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <deque>
#include <fstream>
#include <iostream>
#include <memory>
#include <thread>

#include "context.hpp"
#include "faults/bit_diff.hpp"
#include "faults/fault_mask.hpp"
#include "faults_render.hpp"
#include "lbp/bytes.hpp"
#include "ops/errors.hpp"
#include "ops/live_source.hpp"
#include "ops/signals.hpp"
#include "passive.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;
using Clock = std::chrono::steady_clock;
using WallClock = std::chrono::system_clock;

// A lost card is retried at the sample interval, but not more often than this: opening a
// vanished port or waiting out a timeout every 20 ms would only spin.
constexpr std::chrono::milliseconds kMinRetry{500};
constexpr std::chrono::milliseconds kSleepSlice{20};  // how fast Ctrl-C is noticed
constexpr std::size_t kEventsShown = 12;

struct WatchOptions {
  unsigned interval_ms = 200;
  std::uint64_t count = 0;  // 0: no limit
  double duration_s = 0;    // 0: no limit
  bool plain = false;
  bool registers = false;  // Ethernet: passthrough register reads instead of normal mode
  bool passive = false;    // Ethernet beside a running host: its process data, reads only
  double busv_step_v = 0.5;
  std::string log;
};

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

const char* kind_name(Kind k) {
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

struct Event {
  WallClock::time_point when;
  Kind kind = Kind::FaultSet;
  std::string text;  // one line a person can act on
  std::optional<unsigned> bit;
  std::string name;
};

struct Sample {
  WallClock::time_point when;
  double elapsed_s = 0;
  Readings r;
};

struct Summary {
  std::uint64_t samples = 0;
  double elapsed_s = 0;
  std::uint64_t fault_changes = 0;
  std::uint64_t reconnects = 0;
  bool connected = true;
};

// ------------------------------------------------------------------ formatting
std::string clock_text(WallClock::time_point t, bool with_date) {
  const auto tt = WallClock::to_time_t(t);
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count() % 1000;
  std::tm tm{};
  localtime_r(&tt, &tm);
  char buf[40];
  std::strftime(buf, sizeof buf, with_date ? "%Y-%m-%dT%H:%M:%S" : "%H:%M:%S", &tm);
  char out[48];
  std::snprintf(out, sizeof out, "%s.%03d", buf, static_cast<int>(ms));
  return out;
}

std::string fixed(const std::optional<double>& v, const char* unit) {
  if (!v) return "?";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f%s", *v, unit);
  return buf;
}

bool output_on(const Readings& r) {
  return F::mask_state(r.fault, r.faultmask.value_or(F::kNothingMasked)).fault_output_on();
}

std::string bit_names(F::Register reg, std::uint16_t value) {
  std::string out;
  for (const auto& b : F::decode(reg, value).bits) out += (out.empty() ? "" : " ") + b.label();
  return out;
}

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

// ------------------------------------------------------------------ events from two samples
Event bit_event(WallClock::time_point when, Kind kind, const F::DecodedBit& b) {
  Event e{when, kind, {}, b.bit, b.label()};
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

void add_bits(std::vector<Event>& out, WallClock::time_point when, const F::BitChanges& c, Kind rose,
              Kind fell) {
  for (const auto& b : c.rose) out.push_back(bit_event(when, rose, b));
  for (const auto& b : c.fell) out.push_back(bit_event(when, fell, b));
}

std::vector<Event> changes(const Readings& before, const Readings& after, WallClock::time_point when) {
  std::vector<Event> out;
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
std::vector<Event> warning_events(const Readings* before, const Readings& after, WallClock::time_point when) {
  std::vector<Event> out;
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

// ------------------------------------------------------------------ CSV time series
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string joined(const std::vector<Event>& events) {
  std::string out;
  for (const auto& e : events) out += (out.empty() ? "" : " | ") + e.text;
  return out;
}

class CsvLog {
 public:
  explicit CsvLog(const std::string& path) : out_(path, std::ios::out | std::ios::trunc) {
    if (!out_) throw UsageError("cannot write the log file " + path + ": check the directory exists");
    out_ << "time,elapsed_s,busv_v,temperature_c,brake_on,status,fault,faultmask,fault_output_on,"
            "fault_bits,status_bits,events\n";
    out_.flush();
  }

  void sample(const Sample& s, const std::vector<Event>& events) {
    const auto& r = s.r;
    char elapsed[32];
    std::snprintf(elapsed, sizeof elapsed, "%.3f", s.elapsed_s);
    out_ << clock_text(s.when, true) << "," << elapsed << "," << fixed(r.busv_v, "") << ","
         << fixed(r.temperature_c, "") << "," << (brake_on(r) ? 1 : 0) << "," << lbp::hex_value(r.status, 4)
         << "," << lbp::hex_value(r.fault, 4) << "," << (r.faultmask ? lbp::hex_value(*r.faultmask, 4) : "")
         << "," << (output_on(r) ? 1 : 0) << "," << csv_field(bit_names(F::Register::Fault, r.fault)) << ","
         << csv_field(bit_names(F::Register::Status, r.status)) << "," << csv_field(joined(events)) << "\n";
    out_.flush();  // a watch ends with Ctrl-C or a crash: keep every row written so far
  }

  // A row without readings: the card could not be read (a gap in the series).
  void gap(const Event& e, double elapsed_s) {
    char elapsed[32];
    std::snprintf(elapsed, sizeof elapsed, "%.3f", elapsed_s);
    out_ << clock_text(e.when, true) << "," << elapsed << ",,,,,,,,,," << csv_field(e.text) << "\n";
    out_.flush();
  }

 private:
  std::ofstream out_;
};

// ------------------------------------------------------------------ views
class View {
 public:
  virtual ~View() = default;
  virtual void start(const std::string& target, const WatchOptions& o) = 0;
  virtual void sample(const Sample& s, const Readings* previous, const std::vector<Event>& events) = 0;
  // Connection events that come without a sample (lost contact).
  virtual void event(const Event& e) = 0;
  virtual void finish(const Summary& s) = 0;
};

std::string counted(std::uint64_t n, const std::string& what) {
  return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

std::string summary_text(const Summary& s) {
  return "watch: " + counted(s.samples, "sample") + " in " + seconds_text(s.elapsed_s) + ", " +
         counted(s.fault_changes, "FAULT change") + ", " + counted(s.reconnects, "reconnect") +
         (s.connected ? "" : "; no contact with the card at the end");
}

std::string start_text(const std::string& target, const WatchOptions& o) {
  return "watching the 8I20 on " + target + " every " + std::to_string(o.interval_ms) + " ms; Ctrl-C stops";
}

// Lines for pipes, files and tests: one per sample, one per event, '*' marks a changed value.
class PlainView : public View {
 public:
  void start(const std::string& target, const WatchOptions& o) override {
    std::cout << start_text(target, o) << "\n" << std::flush;
  }
  void sample(const Sample& s, const Readings* previous, const std::vector<Event>& events) override {
    const auto& r = s.r;
    const auto mark = [&](bool changed) { return previous && changed ? "*" : ""; };
    std::cout << clock_text(s.when, false) << "  BUSV " << fixed(r.busv_v, " V") << "  TEMP "
              << fixed(r.temperature_c, " degC") << "  brake " << (brake_on(r) ? "on" : "off")
              << mark(previous && brake_on(*previous) != brake_on(r)) << "  STATUS "
              << lbp::hex_value(r.status, 4) << mark(previous && previous->status != r.status) << "  FAULT "
              << lbp::hex_value(r.fault, 4) << mark(previous && previous->fault != r.fault) << "  output "
              << (output_on(r) ? "ON" : "OFF") << mark(previous && output_on(*previous) != output_on(r));
    if (r.faultmask)
      std::cout << "  FAULTMASK " << lbp::hex_value(*r.faultmask, 4)
                << mark(previous && previous->faultmask != r.faultmask);
    std::cout << "\n";
    for (const auto& e : events) event(e);
    std::cout << std::flush;
  }
  void event(const Event& e) override {
    std::cout << clock_text(e.when, false) << "  * " << e.text << "\n" << std::flush;
  }
  void finish(const Summary& s) override { std::cout << summary_text(s) << "\n"; }
};

// JSON lines: one object per sample, per connection event, and a summary at the end.
class JsonView : public View {
 public:
  void start(const std::string& target, const WatchOptions& o) override {
    emit(app::Json::object().set("type", "start").set("target", target).set("interval_ms", o.interval_ms));
  }
  void sample(const Sample& s, const Readings*, const std::vector<Event>& events) override {
    auto j = app::Json::object();
    j.set("type", "sample").set("time", clock_text(s.when, true)).set("elapsed_s", s.elapsed_s);
    j.set("fault", s.r.fault).set("status", s.r.status);
    j.set("faultmask", s.r.faultmask ? app::Json(*s.r.faultmask) : app::Json());
    j.set("fault_output_on", output_on(s.r)).set("readings", readings_json(s.r));
    auto arr = app::Json::array();
    for (const auto& e : events) arr.push(event_json(e));
    j.set("events", std::move(arr));
    emit(j);
  }
  void event(const Event& e) override { emit(event_json(e).set("type", "event")); }
  void finish(const Summary& s) override {
    auto j = app::Json::object();
    j.set("type", "summary").set("samples", s.samples).set("elapsed_s", s.elapsed_s);
    j.set("fault_changes", s.fault_changes).set("reconnects", s.reconnects).set("connected", s.connected);
    emit(j);
  }

 private:
  static app::Json event_json(const Event& e) {
    auto j = app::Json::object();
    j.set("time", clock_text(e.when, true)).set("kind", kind_name(e.kind)).set("text", e.text);
    j.set("bit", e.bit ? app::Json(*e.bit) : app::Json())
        .set("name", e.name.empty() ? app::Json() : app::Json(e.name));
    return j;
  }
  void emit(const app::Json& j) { std::cout << j.dump(0) << "\n" << std::flush; }
};

// ------------------------------------------------------------------ the terminal view
namespace ansi {
constexpr const char* kHome = "\x1b[H";
constexpr const char* kClearLine = "\x1b[K";
constexpr const char* kClearBelow = "\x1b[J";
constexpr const char* kClearScreen = "\x1b[2J";
constexpr const char* kHideCursor = "\x1b[?25l";
constexpr const char* kShowCursor = "\x1b[?25h";
constexpr const char* kReset = "\x1b[0m";
constexpr const char* kBold = "\x1b[1m";
constexpr const char* kReverse = "\x1b[7m";
constexpr const char* kRed = "\x1b[1;31m";
constexpr const char* kGreen = "\x1b[32m";
constexpr const char* kYellow = "\x1b[33m";
}  // namespace ansi

std::size_t terminal_width() {
  winsize ws{};
  if (ioctl(STDOUT_FILENO, TIOCGWINSZ, &ws) == 0 && ws.ws_col >= 40) return ws.ws_col;
  return 100;
}

// Redraws the whole screen each sample. A value that changed in the last few seconds is
// shown in reverse video so a glance catches it; faults are red, recovery green.
class AnsiView : public View {
 public:
  explicit AnsiView(bool color) : color_(color) {}
  ~AnsiView() override { std::cout << ansi::kShowCursor << std::flush; }  // also on an exception

  void start(const std::string& target, const WatchOptions& o) override {
    header_ = "i20 watch: " + start_text(target, o);
    std::cout << ansi::kHideCursor << ansi::kClearScreen << std::flush;
  }
  void sample(const Sample& s, const Readings* previous, const std::vector<Event>& events) override {
    note_changes(s, previous);
    for (const auto& e : events) remember(e);
    last_ = s;
    lost_.reset();
    draw();
  }
  void event(const Event& e) override {
    remember(e);
    if (e.kind == Kind::Lost) lost_ = e;
    draw();
  }
  void finish(const Summary& s) override {
    std::cout << ansi::kShowCursor << summary_text(s) << "\n" << std::flush;
  }

 private:
  using Field = std::size_t;
  enum : Field { kBrake, kStatus, kFault, kOutput, kMask, kFields };

  std::string paint(const char* code, const std::string& text) const {
    return color_ ? code + text + ansi::kReset : text;
  }
  std::string fresh(Field f, const std::string& text) const {
    const bool recent = changed_at_[f] && Clock::now() - *changed_at_[f] < std::chrono::seconds(3);
    return recent ? paint(ansi::kReverse, text) : text;
  }
  void note_changes(const Sample& s, const Readings* p) {
    if (!p) return;
    const auto now = Clock::now();
    const bool changed[kFields] = {brake_on(*p) != brake_on(s.r), p->status != s.r.status,
                                   p->fault != s.r.fault, output_on(*p) != output_on(s.r),
                                   p->faultmask != s.r.faultmask};
    for (Field f = 0; f < kFields; ++f)
      if (changed[f]) changed_at_[f] = now;
  }
  void remember(const Event& e) {
    events_.push_back(e);
    while (events_.size() > kEventsShown) events_.pop_front();
  }
  std::string clip(const std::string& s) const {
    const auto width = terminal_width() - 1;
    return s.size() > width ? s.substr(0, width - 3) + "..." : s;
  }
  void draw() const;
  void draw_values(std::vector<std::string>& lines) const;
  void draw_faults(std::vector<std::string>& lines) const;
  void draw_events(std::vector<std::string>& lines) const;

  bool color_;
  std::string header_;
  std::optional<Sample> last_;
  std::optional<Event> lost_;
  std::deque<Event> events_;
  std::optional<Clock::time_point> changed_at_[kFields];
};

void AnsiView::draw_values(std::vector<std::string>& lines) const {
  const auto& r = last_->r;
  const bool on = output_on(r);
  lines.push_back("  Bus voltage   " + fixed(r.busv_v, " V"));
  lines.push_back("  Temperature   " + fixed(r.temperature_c, " degC"));
  std::string warning;  // an escalated STATUS bit (the brake on above BRAKEONV) says why here
  for (const auto& l : live_status_report(r).lines)
    if (l.escalated) warning += "  " + paint(ansi::kRed, "WARNING: " + l.name + " with " + l.evidence);
  lines.push_back("  Brake         " + fresh(kBrake, brake_on(r) ? "ON" : "off") +
                  ((r.status & (1u << 2)) ? "  (has been on: BRAKEWASONSTATUS)" : "") + warning);
  const std::string fault =
      lbp::hex_value(r.fault, 4) + "  " + (r.fault ? bit_names(F::Register::Fault, r.fault) : "none");
  lines.push_back("  FAULT         " + fresh(kFault, r.fault ? paint(ansi::kRed, clip(fault)) : fault));
  lines.push_back("  Fault output  " +
                  fresh(kOutput, on ? paint(ansi::kGreen, "ON") : paint(ansi::kRed, "OFF: drive stopped")));
  lines.push_back("  STATUS        " + fresh(kStatus, clip(lbp::hex_value(r.status, 4) + "  " +
                                                           bit_names(F::Register::Status, r.status))));
  if (r.faultmask)
    lines.push_back("  FAULTMASK     " + fresh(kMask, lbp::hex_value(*r.faultmask, 4)) +
                    (*r.faultmask == F::kNothingMasked ? "  nothing masked" : "  some faults masked"));
}

void AnsiView::draw_faults(std::vector<std::string>& lines) const {
  const auto report = F::fault_report(last_->r.fault, last_->r.faultmask);
  for (const auto& line : report.lines) {
    const CauseNow c = cause_now(line.bit, last_->r);
    std::string text = "  " + bit_label(line);
    if (c.state != CauseNow::Unknown)
      text += (c.state == CauseNow::Present ? ": cause present: " : ": cause gone: ") + c.evidence;
    lines.push_back(clip(text));
    // The check gets a line of its own: it is the part a person acts on, so never clip it away first.
    if (!line.checks.empty()) lines.push_back(clip("      check: " + line.checks.front()));
  }
}

void AnsiView::draw_events(std::vector<std::string>& lines) const {
  lines.push_back(paint(ansi::kBold, "Events (newest last)"));
  if (events_.empty()) lines.push_back("  none yet");
  for (const auto& e : events_) {
    const std::string text = clip("  " + clock_text(e.when, false) + "  " + e.text);
    const bool bad = e.kind == Kind::FaultSet || e.kind == Kind::Lost || e.kind == Kind::Restarted;
    const bool good = e.kind == Kind::FaultCleared || e.kind == Kind::Reconnected;
    lines.push_back(bad ? paint(ansi::kRed, text) : good ? paint(ansi::kGreen, text) : text);
  }
}

void AnsiView::draw() const {
  std::vector<std::string> lines{paint(ansi::kBold, clip(header_)) + "    " +
                                 clock_text(WallClock::now(), false)};
  if (lost_)
    lines.push_back(paint(ansi::kYellow, clip("NO CONTACT since " + clock_text(lost_->when, false) +
                                              ": retrying; values below are the last ones read")));
  else
    lines.push_back("");
  if (last_) {
    draw_values(lines);
    lines.push_back("");
    if (last_->r.fault) {
      lines.push_back(paint(ansi::kBold, "What to check now"));
      draw_faults(lines);
      lines.push_back("");
    }
  }
  draw_events(lines);
  std::string frame = ansi::kHome;
  for (const auto& l : lines) frame += l + ansi::kClearLine + "\n";
  std::cout << frame << ansi::kClearBelow << std::flush;
}

// ------------------------------------------------------------------ the loop
class Watcher {
 public:
  // The first look is always a register read, so latched faults are shown as they are;
  // on Ethernet (unless --registers) the watch then goes on in SSLBP normal mode.
  Watcher(Context& ctx, const WatchOptions& o, View& view, CsvLog* log)
      : ctx_(ctx),
        o_(o),
        view_(view),
        log_(log),
        interval_(o.interval_ms),
        source_(ops::make_live_source(ctx.session(), ops::LiveMode::Registers)) {}

  void run();

 private:
  bool done() const;
  bool sleep_until(Clock::time_point t) const;
  Readings read() { return source_->read(); }
  void record(const Readings& r, std::vector<Event> events);
  void sample_once();
  void lose(const std::string& why);
  std::vector<Event> restart_events(const Readings& r);
  double elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
  std::string target() { return source_->describe(); }

  void switch_to_normal_mode(std::vector<Event>& events);

  Context& ctx_;
  const WatchOptions& o_;
  View& view_;
  CsvLog* log_;
  std::chrono::milliseconds interval_;
  Clock::time_point start_;
  std::optional<Readings> previous_;
  std::optional<Clock::time_point> lost_at_;  // set while the card cannot be read
  std::string where_;
  Summary summary_;
  std::unique_ptr<ops::LiveSource> source_;
};

bool Watcher::done() const {
  if (ops::stop_requested()) return true;
  if (o_.count && summary_.samples >= o_.count) return true;
  return o_.duration_s > 0 && elapsed() >= o_.duration_s;
}

// Sleeps in slices so Ctrl-C and --duration end the watch promptly. False: stop now.
bool Watcher::sleep_until(Clock::time_point t) const {
  while (Clock::now() < t) {
    if (done()) return false;
    std::this_thread::sleep_for(std::min<Clock::duration>(kSleepSlice, t - Clock::now()));
  }
  return !done();
}

std::vector<Event> Watcher::restart_events(const Readings& r) {
  std::vector<Event> out;
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

void Watcher::record(const Readings& r, std::vector<Event> events) {
  Sample s{WallClock::now(), elapsed(), r};
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
  ++summary_.samples;
  view_.sample(s, previous_ ? &*previous_ : nullptr, events);
  if (log_) log_->sample(s, events);
  previous_ = r;
}

void Watcher::lose(const std::string& why) {
  lost_at_ = Clock::now();
  summary_.connected = false;
  const Event e{WallClock::now(),
                Kind::Lost,
                "lost contact with the 8I20 on " + where_ + ": " + why + "; retrying every " +
                    seconds_text(std::chrono::duration<double>(std::max(interval_, kMinRetry)).count()) +
                    " (Ctrl-C stops)",
                {},
                {}};
  view_.event(e);
  if (log_) log_->gap(e, elapsed());
  source_->reconnect();  // drop the link: the port may have gone away with the adapter
}

void Watcher::sample_once() {
  std::vector<Event> events;
  try {
    const Readings r = read();
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
    record(r, std::move(events));
  } catch (const ops::Cancelled&) {
    return;  // Ctrl-C during a read: done() ends the loop
  } catch (const UsageError&) {
    throw;
  } catch (const Error& e) {
    if (lost_at_) {
      source_->reconnect();  // still away: try a fresh open next time
      return;
    }
    lose(e.what());
  }
}

// SSLBP's normal start clears faults and enables the current loop (manual, 8I20 DEVICE
// SPECIFIC SETUP): only after the latched faults were reported, and saying so.
void Watcher::switch_to_normal_mode(std::vector<Event>& events) {
  if (o_.registers || !ops::is_eth_target(ctx_.session())) return;
  source_->reconnect();  // close the setup-mode passthrough before the port is re-moded
  source_ = ops::make_live_source(ctx_.session(), ops::LiveMode::NormalModeOnEthernet);
  events.push_back({WallClock::now(),
                    Kind::Mode,
                    "switching to SSLBP normal mode for the live view: its start CLEARS the latched faults "
                    "above and enables the current loop (QSETPOINT stays 0); use --registers to keep reading "
                    "registers",
                    {},
                    {}});
}

void Watcher::run() {
  start_ = Clock::now();
  const Readings first = read();  // a card that cannot be read at all is an error, not a wait
  where_ = target();
  view_.start(where_, o_);
  std::vector<Event> initial;
  for (const auto& b : F::decode_fault(first.fault).bits)
    initial.push_back(bit_event(WallClock::now(), Kind::FaultSet, b));
  switch_to_normal_mode(initial);
  record(first, std::move(initial));
  auto next = start_ + interval_;
  while (!done()) {
    if (!sleep_until(next)) break;
    sample_once();
    const auto step = lost_at_ ? std::max(interval_, kMinRetry) : interval_;
    next += step;
    if (next < Clock::now()) next = Clock::now() + step;  // a slow read skips ticks, never bunches them
  }
  summary_.elapsed_s = elapsed();
  view_.finish(summary_);
  if (ops::stop_requested()) ctx_.record(ops::Outcome::Interrupted);  // after leaving the card as it was
}

// ------------------------------------------------------------------ registration
std::unique_ptr<View> make_view(const Context& ctx, const WatchOptions& o) {
  if (ctx.options.json) return std::make_unique<JsonView>();
  const char* term = std::getenv("TERM");
  const bool dumb = term && std::string(term) == "dumb";
  if (o.plain || dumb || !isatty(STDOUT_FILENO)) return std::make_unique<PlainView>();
  return std::make_unique<AnsiView>(std::getenv("NO_COLOR") == nullptr);
}

void run_watch(Context& ctx, const WatchOptions& o) {
  if (o.passive) {
    if (o.registers)
      throw UsageError(
          "watch: --passive and --registers exclude each other (--passive reads no register through the "
          "passthrough)");
    run_passive_watch(ctx, PassiveWatchOptions{.interval_ms = o.interval_ms,
                                               .count = o.count,
                                               .duration_s = o.duration_s,
                                               .busv_step_v = o.busv_step_v,
                                               .log = o.log});
    return;
  }
  std::unique_ptr<CsvLog> log;
  if (!o.log.empty()) log = std::make_unique<CsvLog>(o.log);  // a bad path fails before the link opens
  auto view = make_view(ctx, o);
  Watcher(ctx, o, *view, log.get()).run();
}

}  // namespace

void register_watch_command(CLI::App& app, Context& ctx) {
  auto o = std::make_shared<WatchOptions>();
  auto* watch = app.add_subcommand(
      "watch",
      "Live view of bus voltage, card temperature, brake, STATUS and FAULT; changes are timestamped and "
      "explained. Survives a card reset or an unplugged adapter (reconnects). Ctrl-C stops");
  watch->add_option("--interval", o->interval_ms, "Time between samples, ms")
      ->check(CLI::Range(10u, 3600000u))
      ->capture_default_str();
  watch
      ->add_option("--count", o->count,
                   "Stop after N samples (time without contact to the card does not count)")
      ->check(CLI::PositiveNumber);
  watch->add_option("--duration", o->duration_s, "Stop after S seconds, e.g. 2.5")
      ->check(CLI::PositiveNumber);
  watch->add_flag("--plain", o->plain,
                  "One line per sample, no screen redraw (automatic when stdout is no terminal)");
  watch->add_flag(
      "--registers", o->registers,
      "Ethernet targets: keep reading registers through the setup-mode passthrough instead of switching to "
      "SSLBP normal mode after the first look (normal mode feeds the watchdog, but its start clears latched "
      "faults)");
  watch->add_flag(
      "--passive", o->passive,
      passive_flag_help("every 8I20 of the card at once, with a timestamped line per change of bus voltage, "
                        "temperature, FAULT or STATUS,") +
          "; --interval 50 or more");
  watch
      ->add_option("--busv-step", o->busv_step_v,
                   "--passive: report a bus voltage change of at least this much, V")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  watch->add_option("--log", o->log, "Also write a CSV time series (one row per sample, gaps marked)")
      ->type_name("FILE.csv");
  watch->callback([&ctx, o] { run_watch(ctx, *o); });
}

}  // namespace i20::cli
