// SPDX-License-Identifier: GPL-2.0-or-later
#include "passive.hpp"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "csv_log.hpp"
#include "faults/decode.hpp"
#include "faults_render.hpp"
#include "lbp/bytes.hpp"
#include "ops/core/errors.hpp"
#include "ops/watch/passive_monitor.hpp"
#include "ops/watch/passive_watch.hpp"
#include "ops/scan.hpp"
#include "ops/core/timing.hpp"
#include "terminal.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;
using WallClock = std::chrono::system_clock;
using ops::PassiveChange;
using ops::PassiveSample;

std::string card_text(const Context& ctx) {
  const auto& o = ctx.options.target;
  if (!o.eth.empty()) return o.eth;
  return o.port;
}

// The card named by --eth (an address or an eth:// URL) or an eth:// --port. A passive
// monitor always watches every channel of the card.
ops::HostPort passive_host_port(const Context& ctx, const char* command) {
  const auto host_port = ops::ethernet_host_port(ctx.options.target);
  if (!host_port)
    throw UsageError(
        std::string(command) +
        " --passive reads what a running host leaves in an Ethernet card's SSERIAL registers: give "
        "the card's address, e.g. i20 --eth 192.168.1.121 " +
        command + " --passive");
  return *host_port;
}

ops::PassiveMonitorOptions monitor_options(const Context& ctx) {
  return {.read = ops::timing::passive(ctx.options.link)};
}

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

std::string fixed(double v, const char* format = "%.2f") {
  char buf[32];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string bit_names(F::Register reg, std::uint16_t value) {
  std::string out;
  for (const auto& b : F::decode(reg, value).bits) {
    if (!out.empty()) out.append(" ");  // append(): GCC 12 -O3 -Wrestrict false positive in operator+
    out.append(b.label());
  }
  return out;
}

std::string amp_line(const ops::PassiveAmplifier& a) {
  const auto& d = a.data;
  std::string s = "port " + std::to_string(d.port) + " ch " + std::to_string(d.channel) + ": ";
  if (!d.live()) return s + "8I20, not in a running cycle (" + a.link_status + ")";
  s += "BUSV " + fixed(d.busv_v()) + " V  TEMP " + std::to_string(d.temperature_c()) + " degC  STATUS " +
       lbp::hex_value(d.status(), 4) + "  FAULT " + lbp::hex_value(d.fault(), 4);
  if (d.fault()) s += " (" + bit_names(F::Register::Fault, d.fault()) + ")";
  return s;
}

app::Json amp_json(const ops::PassiveAmplifier& a) {
  const auto& d = a.data;
  auto j = app::Json::object();
  j.set("port", d.port)
      .set("channel", d.channel)
      .set("target", a.target)
      .set("linuxcnc_name", a.linuxcnc_name);
  j.set("live", d.live()).set("cs", lbp::hex_value(d.cs, 8)).set("link_status", a.link_status);
  j.set("doit_failed", d.doit_failed);
  j.set("busv_v", d.busv_v()).set("temperature_c", d.temperature_c());
  j.set("fault", static_cast<unsigned>(d.fault())).set("status", static_cast<unsigned>(d.status()));
  j.set("fault_bits", bit_names(F::Register::Fault, d.fault()));
  j.set("status_bits", bit_names(F::Register::Status, d.status()));
  return j;
}

app::Json change_json(const PassiveChange& c) {
  auto j = app::Json::object();
  j.set("time", clock_text(c.when, true)).set("kind", ops::to_string(c.kind)).set("text", c.text);
  j.set("port", c.port ? app::Json(*c.port) : app::Json())
      .set("channel", c.channel ? app::Json(*c.channel) : app::Json());
  j.set("bit", c.bit ? app::Json(*c.bit) : app::Json())
      .set("name", c.name.empty() ? app::Json() : app::Json(c.name));
  return j;
}

// One row per 8I20 per sample; the row carries the changes of that channel.
class PassiveCsv {
 public:
  explicit PassiveCsv(const std::string& path)
      : log_(path,
             "time,elapsed_s,port,channel,live,busv_v,temperature_c,status,fault,fault_bits,status_bits,"
             "events\n") {}
  void sample(const PassiveSample& s) {
    std::ostringstream rows;
    for (const auto& a : s.amplifiers) {
      const auto& d = a.data;
      std::string events;
      for (const auto& c : s.changes)
        if (c.port == d.port && c.channel == d.channel) events += (events.empty() ? "" : " | ") + c.text;
      rows << clock_text(s.when, true) << "," << fixed(s.elapsed_s, "%.3f") << "," << d.port << ","
           << d.channel << "," << (d.live() ? 1 : 0) << "," << fixed(d.busv_v()) << "," << d.temperature_c()
           << "," << lbp::hex_value(d.status(), 4) << "," << lbp::hex_value(d.fault(), 4) << ","
           << csv_field(bit_names(F::Register::Fault, d.fault())) << ","
           << csv_field(bit_names(F::Register::Status, d.status())) << "," << csv_field(events) << "\n";
    }
    log_.write(rows.str());
  }

 private:
  CsvLog log_;
};

// Two samples a request spacing apart: the second one knows whether another host talks.
PassiveSample two_samples(ops::PassiveMonitor& monitor) {
  monitor.sample();
  return monitor.sample();
}

std::string host_text(const PassiveSample& s) {
  const auto active = s.host_active();
  if (!active) return "unknown";
  return *active ? "running (" + std::to_string(*s.foreign_packets) +
                       " packets of another host between two reads)"
                 : "silent: no other host talked to the card between two reads, the values are stale";
}

// JSON lines, as `watch --json`: one object per line.
void emit_line(const app::Json& j) {
  std::cout << j.dump(0) << "\n" << std::flush;
}

// What `watch --passive` shows of the loop (lib/ops/passive_watch): a line per change, or
// JSON lines, and the CSV series.
class PassiveWatchView : public ops::PassiveWatchSink {
 public:
  PassiveWatchView(bool json, PassiveCsv* log) : json_(json), log_(log) {}

  void link(const ops::PassiveLinkEvent& e) override {
    if (json_)
      emit_line(app::Json::object()
                    .set("type", "event")
                    .set("time", clock_text(e.when, true))
                    .set("kind", ops::to_string(e.kind))
                    .set("text", e.text));
    else
      std::cout << clock_text(e.when, false) << "  * " << e.text << "\n" << std::flush;
  }

  void sample(const PassiveSample& s) override {
    if (json_) {
      auto j = app::Json::object();
      j.set("type", "sample").set("time", clock_text(s.when, true)).set("elapsed_s", s.elapsed_s);
      j.set("host_active", s.host_active() ? app::Json(*s.host_active()) : app::Json());
      auto amps = app::Json::array();
      for (const auto& a : s.amplifiers) amps.push(amp_json(a));
      j.set("amplifiers", std::move(amps));
      auto events = app::Json::array();
      for (const auto& c : s.changes) events.push(change_json(c));
      j.set("events", std::move(events));
      emit_line(j);
    } else {
      if (first_ && s.amplifiers.empty())
        std::cout << clock_text(s.when, false)
                  << "  no 8I20 in a running cycle on any SSERIAL channel (is the host "
                     "running? `i20 --eth ... scan --passive` lists the channels)\n";
      for (const auto& c : s.changes) std::cout << clock_text(c.when, false) << "  * " << c.text << "\n";
      std::cout << std::flush;
    }
    first_ = false;
    if (log_) log_->sample(s);
    app::require_stdout();  // its reader gone (`| head -1`): stop, exit 6, instead of polling for nobody
  }

 private:
  bool json_;
  PassiveCsv* log_;  // none without --log
  bool first_ = true;
};

}  // namespace

std::string passive_flag_help(const std::string& what) {
  return "Ethernet beside a running machine: " + what +
         " only from the process data the running host's DOITs leave in the SSERIAL registers (CS, "
         "INTERFACE0/1, "
         "DATA). Reads only: no write, no DOIT, no start or stop; at most " +
         std::to_string(ops::kPassiveMaxRequestsPerSecond) + " UDP requests a second";
}

std::string passive_hint(const Context& ctx) {
  const std::string card = card_text(ctx).empty() ? "IP" : card_text(ctx);
  return "; to only read beside it, without stopping anything: i20 --eth " + card +
         " watch --passive (also faults --passive, scan --passive)";
}

void run_passive_watch(Context& ctx, const PassiveWatchOptions& o) {
  const auto host_port = passive_host_port(ctx, "watch");
  const auto spacing = 1000u / ops::kPassiveMaxRequestsPerSecond;
  if (o.interval_ms < spacing)
    throw UsageError("watch --passive --interval " + std::to_string(o.interval_ms) +
                     ": the passive monitor sends at most " +
                     std::to_string(ops::kPassiveMaxRequestsPerSecond) +
                     " requests a second, use --interval " + std::to_string(spacing) + " or more");
  std::unique_ptr<PassiveCsv> log;
  if (!o.log.empty()) log = std::make_unique<PassiveCsv>(o.log);
  auto options = monitor_options(ctx);
  options.busv_step_v = o.busv_step_v;
  ops::PassiveMonitor monitor(host_port, options);
  const bool json = ctx.options.json;
  if (json) {
    emit_line(app::Json::object()
                  .set("type", "start")
                  .set("mode", "passive")
                  .set("card", monitor.describe())
                  .set("interval_ms", o.interval_ms)
                  .set("max_requests_per_second", ops::kPassiveMaxRequestsPerSecond));
  } else {
    std::cout << "watching every 8I20 of the " << monitor.describe() << " passively (reads only, every "
              << o.interval_ms << " ms, at most " << ops::kPassiveMaxRequestsPerSecond
              << " requests a second); a line per change; Ctrl-C stops\n"
              << std::flush;
  }
  PassiveWatchView view(json, log.get());
  const auto summary = ops::run_passive_monitor(
      monitor, {std::chrono::milliseconds(o.interval_ms), o.count, o.duration_s}, view);
  if (json)
    emit_line(app::Json::object()
                  .set("type", "summary")
                  .set("samples", summary.samples)
                  .set("elapsed_s", summary.elapsed_s)
                  .set("changes", summary.changes)
                  .set("missed", summary.missed)
                  .set("requests", summary.requests));
  else
    std::cout << "watch --passive: " << summary.samples << " samples in " << fixed(summary.elapsed_s, "%.1f")
              << " s, " << summary.changes << " changes, " << summary.missed << " missed, "
              << summary.requests << " UDP requests, at least " << 1000 / ops::kPassiveMaxRequestsPerSecond
              << " ms apart\n";
  if (summary.outcome == ops::Outcome::Interrupted) ctx.record(ops::Outcome::Interrupted);
}

void run_passive_faults(Context& ctx) {
  const auto host_port = passive_host_port(ctx, "faults");
  ops::PassiveMonitor monitor(host_port, monitor_options(ctx));
  const auto s = two_samples(monitor);
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("source", "passive").set("card", monitor.describe()).set("host", host_text(s));
    auto amps = app::Json::array();
    for (const auto& a : s.amplifiers) {
      auto aj = amp_json(a);
      aj.set("fault_report", report_json(F::fault_report(a.readings.fault), &a.readings));
      aj.set("status_report", report_json(live_status_report(a.readings)));
      aj.set("readings", readings_json(a.readings));
      amps.push(std::move(aj));
    }
    j.set("amplifiers", std::move(amps));
    ctx.print_json(j);
    return;
  }
  std::cout << monitor.describe()
            << ", read passively (process data of the running host's last DOIT); host: " << host_text(s)
            << "\n";
  if (s.amplifiers.empty()) std::cout << "no 8I20 on any SSERIAL channel (CS names none)\n";
  for (const auto& a : s.amplifiers) {
    std::cout << "\n8I20 on " << a.target << " (LinuxCNC " << a.linuxcnc_name << "): " << amp_line(a) << "\n";
    if (!a.data.live()) continue;
    std::cout << "\n";
    print_fault_report(std::cout, F::fault_report(a.readings.fault));
    std::cout << "\n";
    print_status_report(std::cout, live_status_report(a.readings));
  }
  std::cout << "\nFAULTMASK and the thresholds are parameters, not process data; clearing a fault needs the "
               "running host (its next normal start) or the setup-mode passthrough once it has stopped.\n";
}

void run_passive_scan(Context& ctx) {
  const auto host_port = passive_host_port(ctx, "scan");
  ops::PassiveMonitor monitor(host_port, monitor_options(ctx));
  const auto s = two_samples(monitor);
  const auto& reader = monitor.reader();
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("address", host_port.describe()).set("card", reader.identity().card_name);
    j.set("board", reader.hostmot2().idrom.board_name).set("mode", "passive").set("host", host_text(s));
    auto ports = app::Json::array();
    for (const auto& p : reader.ports()) {
      auto pj = app::Json::object();
      pj.set("port", p.index).set("channels", reader.channels(p.index));
      auto amps = app::Json::array();
      for (const auto& a : s.amplifiers)
        if (a.data.port == p.index) amps.push(amp_json(a));
      pj.set("amplifiers", std::move(amps));
      ports.push(std::move(pj));
    }
    j.set("ports", std::move(ports)).set("requests", s.requests_sent);
    ctx.print_json(j);
    return;
  }
  std::cout << monitor.describe() << ", " << reader.hostmot2().idrom.board_name
            << " (passive: reads only, nothing stopped); host: " << host_text(s) << "\n";
  std::size_t live = 0;
  for (const auto& p : reader.ports()) {
    std::cout << "  SSERIAL port " << p.index << ": " << reader.channels(p.index) << " channel(s)\n";
    bool any = false;
    for (const auto& a : s.amplifiers) {
      if (a.data.port != p.index) continue;
      any = true;
      if (a.data.live()) ++live;
      std::cout << "    ch " << a.data.channel << ": "
                << (a.data.live() ? "8I20 run by the host" : "8I20, not running") << ", BUSV "
                << fixed(a.data.busv_v()) << " V, FAULT " << lbp::hex_value(a.data.fault(), 4) << "  -> "
                << a.target << "  LinuxCNC " << a.linuxcnc_name << "\n";
    }
    if (!any) std::cout << "    no 8I20 the host has started on this port\n";
  }
  std::cout << live
            << " 8I20(s) in the running host's cycle; unit numbers need a setup start (not done passively)\n";
}

}  // namespace i20::cli
