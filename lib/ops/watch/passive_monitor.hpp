// SPDX-License-Identifier: GPL-2.0-or-later
// The passive monitor use case: every 8I20 of a card that another host (LinuxCNC) is
// running, read from the process data that host's DOITs leave in the SSERIAL registers
// (eth/passive_reader.hpp), without a write, a DOIT, a start or a stop, at a bounded
// request rate. Each sample carries what changed since the previous one, timestamped:
// an 8I20 appearing or dropping out of the host's cycle, bus voltage and temperature
// moves, FAULT and STATUS bits (named by the fault table, params/faults.yaml), the host
// going quiet.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "eth/passive_reader.hpp"
#include "ops/faults.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

// At most this many UDP requests a second (ops/core/timing.hpp).
using timing::kPassiveMaxRequestsPerSecond;

struct PassiveChange {
  enum class Kind {
    Joined,       // an 8I20 is in the host's cycle (first sample, or back)
    Left,         // it no longer answers the host's DOITs, or the channel was stopped
    BusVoltage,   // moved by at least the step since the last reported value
    Temperature,  // likewise
    FaultSet,
    FaultCleared,
    StatusSet,
    StatusCleared,
    HostQuiet,   // no packet of another host reached the card: the registers are stale
    HostActive,  // it talks again
  };
  std::chrono::system_clock::time_point when{};
  Kind kind = Kind::Joined;
  std::optional<unsigned> port{}, channel{};  // empty for card-wide changes
  std::string text{};                         // one line a person can act on
  std::optional<unsigned> bit{};              // FAULT/STATUS changes
  std::string name{};                         // the bit's name
};

// "joined", "left", "busv", "temperature", "fault_set", "fault_cleared", "status_set",
// "status_cleared", "host_quiet", "host_active".
const char* to_string(PassiveChange::Kind kind);

// The readings of one channel in the form every fault renderer takes (no FAULTMASK and no
// thresholds: those are parameters, which need the setup-mode passthrough).
FaultReadings readings_of(const eth::ProcessData& data);

struct PassiveAmplifier {
  eth::ProcessData data{};
  FaultReadings readings{};
  std::string linuxcnc_name{};  // hm2_7i96s.0.8i20.0.1
  std::string target{};         // eth://IP/ch1 (or /port1/ch5)
  std::string link_status{};    // CS in words: "ok", "communication error, timeout"
};

struct PassiveSample {
  std::chrono::system_clock::time_point when{};
  double elapsed_s = 0;
  std::vector<PassiveAmplifier> amplifiers{};  // channels with an 8I20 (CS byte 3), live or not
  std::optional<std::uint32_t> foreign_packets{};
  std::vector<PassiveChange> changes{};
  std::uint64_t requests_sent = 0;  // by this monitor so far, the card survey included

  // Another host was seen talking since the previous sample (unknown on the first one).
  std::optional<bool> host_active() const {
    if (!foreign_packets) return std::nullopt;
    return *foreign_packets > 0;
  }
};

struct PassiveMonitorOptions {
  eth::PassiveOptions read;    // timing::passive
  double busv_step_v = 0.5;    // a bus voltage change line at this much movement
  int temperature_step_c = 1;  // and a temperature one
  unsigned board_index = 0;    // for the LinuxCNC names (eth/scan.hpp)
};

class PassiveMonitor {
 public:
  PassiveMonitor(const eth::HostPort& host_port, PassiveMonitorOptions options);
  // Over any transport (tests).
  PassiveMonitor(const eth::HostPort& host_port, std::unique_ptr<eth::Lbp16Transport> bus,
                 PassiveMonitorOptions options);

  // One snapshot of every channel and what changed since the previous one. Throws
  // link::TimeoutError when the card does not answer (nothing was sent again).
  PassiveSample sample();

  const eth::PassiveReader& reader() const { return reader_; }
  const eth::HostPort& host_port() const { return host_port_; }
  // "7I96S at 127.0.0.1:40000 (HOSTMOT2 board MESA7I96)".
  std::string describe() const;

 private:
  struct Reported {
    bool live = false;
    double busv_v = 0;
    int temperature_c = 0;
    std::uint16_t fault = 0, status = 0;
  };
  PassiveAmplifier amplifier(const eth::ProcessData& data) const;
  void compare(const eth::ProcessData& data, PassiveSample& out);

  eth::HostPort host_port_;
  PassiveMonitorOptions options_;
  eth::PassiveReader reader_;
  std::chrono::steady_clock::time_point start_{};
  std::map<std::pair<unsigned, unsigned>, Reported> reported_{};
  std::optional<bool> host_active_{};
};

}  // namespace i20::ops
