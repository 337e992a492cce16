// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/watch/passive_monitor.hpp"

#include <cmath>
#include <cstdio>

#include "eth/scan.hpp"
#include "faults/bit_diff.hpp"
#include "lbp/bytes.hpp"

namespace i20::ops {

namespace F = i20::faults;
using Kind = PassiveChange::Kind;

namespace {

std::string volts(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f V", v);
  return buf;
}

std::string where(const eth::ProcessData& d) {
  return "port " + std::to_string(d.port) + " ch " + std::to_string(d.channel);
}

PassiveChange change(const PassiveSample& s, const eth::ProcessData& d, Kind kind, std::string text) {
  return PassiveChange{
      .when = s.when, .kind = kind, .port = d.port, .channel = d.channel, .text = std::move(text)};
}

void add_bits(PassiveSample& s, const eth::ProcessData& d, const F::BitChanges& c, Kind rose, Kind fell) {
  const bool fault = c.reg == F::Register::Fault;
  const auto one = [&](const F::DecodedBit& b, Kind kind, bool set) {
    std::string text = where(d) + ": " + (fault ? "FAULT " : "STATUS ") + (set ? "set: " : "cleared: ") +
                       b.label() + " (bit " + std::to_string(b.bit) + ")";
    if (set) {
      std::string meaning = b.meaning();
      if (!meaning.empty() && meaning.back() == '.') meaning.pop_back();
      text += ": " + meaning;
      if (fault && b.info && !b.info->checks.empty()) text += "; check: " + b.info->checks.front();
    }
    auto c2 = change(s, d, kind, std::move(text));
    c2.bit = b.bit;
    c2.name = b.label();
    s.changes.push_back(std::move(c2));
  };
  for (const auto& b : c.rose) one(b, rose, true);
  for (const auto& b : c.fell) one(b, fell, false);
}

}  // namespace

const char* to_string(Kind kind) {
  switch (kind) {
    case Kind::Joined: return "joined";
    case Kind::Left: return "left";
    case Kind::BusVoltage: return "busv";
    case Kind::Temperature: return "temperature";
    case Kind::FaultSet: return "fault_set";
    case Kind::FaultCleared: return "fault_cleared";
    case Kind::StatusSet: return "status_set";
    case Kind::StatusCleared: return "status_cleared";
    case Kind::HostQuiet: return "host_quiet";
    case Kind::HostActive: return "host_active";
  }
  return "";
}

FaultReadings readings_of(const eth::ProcessData& data) {
  FaultReadings r;
  r.fault = data.fault();
  r.status = data.status();
  r.busv_v = data.busv_v();
  r.temperature_c = static_cast<double>(data.temperature_c());
  r.not_confirmed = {"FAULTMASK", "BUSUNDERV", "BUSOVERV",
                     "BRAKEONV"};  // parameters: not in the process data
  return r;
}

PassiveMonitor::PassiveMonitor(const eth::HostPort& host_port, PassiveMonitorOptions options)
    : host_port_(host_port),
      options_(options),
      reader_(host_port, options.read),
      start_(std::chrono::steady_clock::now()) {}

PassiveMonitor::PassiveMonitor(const eth::HostPort& host_port, std::unique_ptr<eth::Lbp16Transport> bus,
                               PassiveMonitorOptions options)
    : host_port_(host_port),
      options_(options),
      reader_(std::move(bus), options.read),
      start_(std::chrono::steady_clock::now()) {}

std::string PassiveMonitor::describe() const {
  return reader_.identity().card_name + " at " + host_port_.describe();
}

PassiveAmplifier PassiveMonitor::amplifier(const eth::ProcessData& data) const {
  PassiveAmplifier a;
  a.data = data;
  a.readings = readings_of(data);
  a.linuxcnc_name =
      eth::linuxcnc_device_name(reader_.identity().card_name, options_.board_index, data.port, data.channel);
  a.target =
      eth::EthTarget{.host_port = host_port_, .sserial_port = data.port, .channel = data.channel}.url();
  a.link_status = data.status_register().describe();
  if (data.doit_failed) a.link_status += ", last DOIT failed";
  return a;
}

void PassiveMonitor::compare(const eth::ProcessData& d, PassiveSample& s) {
  const auto key = std::make_pair(d.port, d.channel);
  const auto it = reported_.find(key);
  const bool live = d.live();
  if (it == reported_.end() || it->second.live != live) {
    if (live) {
      s.changes.push_back(change(s, d, Kind::Joined,
                                 where(d) + ": 8I20 in the host's cycle: bus " + volts(d.busv_v()) +
                                     ", card " + std::to_string(d.temperature_c()) + " degC, FAULT " +
                                     lbp::hex_value(d.fault(), 4) + ", STATUS " +
                                     lbp::hex_value(d.status(), 4)));
    } else if (it != reported_.end()) {
      s.changes.push_back(
          change(s, d, Kind::Left,
                 where(d) + ": 8I20 no longer answers the host's DOITs (" + d.status_register().describe() +
                     (d.doit_failed ? ", last DOIT failed" : "") + "): the values below are its last ones"));
    } else {
      s.changes.push_back(change(
          s, d, Kind::Left,
          where(d) + ": 8I20 present but not in a running cycle (" + d.status_register().describe() + ")"));
    }
  }
  Reported before = it == reported_.end() ? Reported{} : it->second;
  Reported now = before;
  now.live = live;
  if (live) {
    // Process data means something only while the channel runs.
    if (it != reported_.end() && before.live) {
      if (std::fabs(d.busv_v() - before.busv_v) >= options_.busv_step_v) {
        s.changes.push_back(
            change(s, d, Kind::BusVoltage,
                   where(d) + ": bus voltage " + volts(before.busv_v) + " -> " + volts(d.busv_v())));
        now.busv_v = d.busv_v();
      }
      if (std::abs(d.temperature_c() - before.temperature_c) >= options_.temperature_step_c) {
        s.changes.push_back(change(s, d, Kind::Temperature,
                                   where(d) + ": card temperature " + std::to_string(before.temperature_c) +
                                       " -> " + std::to_string(d.temperature_c()) + " degC"));
        now.temperature_c = d.temperature_c();
      }
    } else {
      now.busv_v = d.busv_v();
      now.temperature_c = d.temperature_c();
    }
    add_bits(s, d, F::diff(F::Register::Fault, before.fault, d.fault()), Kind::FaultSet, Kind::FaultCleared);
    add_bits(s, d, F::diff(F::Register::Status, before.status, d.status()), Kind::StatusSet,
             Kind::StatusCleared);
    now.fault = d.fault();
    now.status = d.status();
  }
  reported_[key] = now;
}

PassiveSample PassiveMonitor::sample() {
  const auto snap = reader_.read();
  PassiveSample s;
  s.when = snap.wall;
  s.elapsed_s = std::chrono::duration<double>(snap.at - start_).count();
  s.foreign_packets = snap.foreign_packets;
  for (const auto& d : snap.channels) {
    if (!d.is_8i20() && !reported_.contains({d.port, d.channel})) continue;
    if (d.is_8i20()) s.amplifiers.push_back(amplifier(d));
    compare(d, s);
  }
  if (const auto active = s.host_active(); active && active != host_active_) {
    if (!*active)
      s.changes.push_back(PassiveChange{
          .when = s.when,
          .kind = Kind::HostQuiet,
          .text = "no other host talked to the card since the previous read: the running host stopped, the "
                  "values are from its last cycle"});
    else if (host_active_)
      s.changes.push_back(PassiveChange{
          .when = s.when, .kind = Kind::HostActive, .text = "another host talks to the card again"});
    host_active_ = active;
  }
  s.requests_sent = reader_.requests_sent();
  return s;
}

}  // namespace i20::ops
