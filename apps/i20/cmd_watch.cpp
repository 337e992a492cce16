// SPDX-License-Identifier: GPL-2.0-or-later
// i20 watch: a live view of bus voltage, card temperature, brake, STATUS and FAULT.
//
// The loop (sampling, events, reconnects, the switch to SSLBP normal mode) is lib/ops'
// monitor; this file holds its views: a redrawn screen on a terminal, plain lines for pipes
// and files (--plain), and JSON lines (--json); --log adds a CSV series.
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
#include <sstream>

#include "context.hpp"
#include "csv_log.hpp"
#include "faults/fault_mask.hpp"
#include "faults_render.hpp"
#include "lbp/bytes.hpp"
#include "ops/watch/monitor.hpp"
#include "passive.hpp"
#include "terminal.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;
using Clock = std::chrono::steady_clock;
using WallClock = std::chrono::system_clock;

constexpr std::size_t kEventsShown = 12;

using Event = ops::MonitorEvent;
using Kind = ops::MonitorEvent::Kind;
using Sample = ops::MonitorSample;
using Summary = ops::MonitorSummary;
using ops::bit_names;
using ops::output_on;

struct WatchOptions {
  unsigned interval_ms = static_cast<unsigned>(ops::timing::kWatchInterval.count());
  std::uint64_t count = 0;  // 0: no limit
  double duration_s = 0;    // 0: no limit
  bool plain = false;
  bool registers = false;  // Ethernet: passthrough register reads instead of normal mode
  bool passive = false;    // Ethernet beside a running host: its process data, reads only
  double busv_step_v = 0.5;
  std::string log;
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

std::string seconds_text(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f s", s);
  return buf;
}

// ------------------------------------------------------------------ CSV time series
std::string joined(const std::vector<Event>& events) {
  std::string out;
  for (const auto& e : events) out += (out.empty() ? "" : " | ") + e.text;
  return out;
}

class WatchCsv {
 public:
  explicit WatchCsv(const std::string& path)
      : log_(path,
             "time,elapsed_s,busv_v,temperature_c,brake_on,status,fault,faultmask,fault_output_on,"
             "fault_bits,status_bits,events\n") {}

  void sample(const Sample& s, const std::vector<Event>& events) {
    const auto& r = s.r;
    char elapsed[32];
    std::snprintf(elapsed, sizeof elapsed, "%.3f", s.elapsed_s);
    std::ostringstream row;
    row << clock_text(s.when, true) << "," << elapsed << "," << fixed(r.busv_v, "") << ","
        << fixed(r.temperature_c, "") << "," << (brake_on(r) ? 1 : 0) << "," << lbp::hex_value(r.status, 4)
        << "," << lbp::hex_value(r.fault, 4) << "," << (r.faultmask ? lbp::hex_value(*r.faultmask, 4) : "")
        << "," << (output_on(r) ? 1 : 0) << "," << csv_field(bit_names(F::Register::Fault, r.fault)) << ","
        << csv_field(bit_names(F::Register::Status, r.status)) << "," << csv_field(joined(events)) << "\n";
    log_.write(row.str());
  }

  // A row without readings: the card could not be read (a gap in the series).
  void gap(const Event& e, double elapsed_s) {
    char elapsed[32];
    std::snprintf(elapsed, sizeof elapsed, "%.3f", elapsed_s);
    log_.write(clock_text(e.when, true) + "," + elapsed + ",,,,,,,,,," + csv_field(e.text) + "\n");
  }

 private:
  CsvLog log_;
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
    j.set("time", clock_text(e.when, true)).set("kind", ops::to_string(e.kind)).set("text", e.text);
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

// ------------------------------------------------------------------ the views as one sink
// The chosen view, and the CSV series beside it when --log asks for one.
class WatchSink final : public ops::MonitorSink {
 public:
  WatchSink(View& view, WatchCsv* log, const WatchOptions& o) : view_(view), log_(log), o_(o) {}
  // Each call ends by checking stdout: a watch whose reader went away (`| head -1`) stops,
  // exit 6, instead of polling the card for nobody while holding its port.
  void start(const std::string& target, const ops::MonitorOptions&) override {
    view_.start(target, o_);
    app::require_stdout();
  }
  void sample(const Sample& s, const Readings* previous, const std::vector<Event>& events) override {
    view_.sample(s, previous, events);
    if (log_) log_->sample(s, events);
    app::require_stdout();
  }
  void event(const Event& e) override {
    view_.event(e);
    if (log_) log_->gap(e, e.elapsed_s);
    app::require_stdout();
  }
  void finish(const Summary& summary) override {
    view_.finish(summary);
    app::require_stdout();
  }

 private:
  View& view_;
  WatchCsv* log_;
  const WatchOptions& o_;
};

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
  std::unique_ptr<WatchCsv> log;
  if (!o.log.empty()) log = std::make_unique<WatchCsv>(o.log);  // a bad path fails before the link opens
  auto view = make_view(ctx, o);
  WatchSink sink(*view, log.get(), o);
  const ops::MonitorOptions monitor{.interval = std::chrono::milliseconds(o.interval_ms),
                                    .count = o.count,
                                    .duration_s = o.duration_s,
                                    .registers = o.registers};
  ctx.record(ops::run_monitor(ctx.session(), monitor, sink));
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
