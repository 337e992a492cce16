// SPDX-License-Identifier: GPL-2.0-or-later
// Where live FAULT/STATUS/BUSV/TEMPERATURE come from, for `watch` and `faults`:
//  - a card reached by register reads (serial port, simulator, Ethernet passthrough), at
//    addresses confirmed for its firmware (the card's RPC table names them on any card);
//  - for `watch` on an Ethernet target only, after a first register read: SSLBP normal
//    mode, whose DOIT cycles carry bus voltage, temperature, FAULT and STATUS in
//    INTERFACE0/1 (8I20 manual) and keep the 8I20's 40 ms watchdog fed. Its start clears
//    faults and enables the current loop (manual, 8I20 DEVICE SPECIFIC SETUP).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "ops/core/session.hpp"
#include "ops/faults.hpp"

namespace i20::ops {

class LiveSource {
 public:
  virtual ~LiveSource() = default;
  // One set of readings. Throws i20::Error when the card cannot be reached.
  virtual FaultReadings read() = 0;
  // "8I20 on ..." target text, for messages.
  virtual std::string describe() = 0;
  // Drop the connection; the next read() opens it again.
  virtual void reconnect() = 0;
  // "normal mode (DOIT every 10 ms)" or "register reads": for the user.
  virtual std::string method() const = 0;
};

enum class LiveMode {
  Registers,             // register reads on every transport (read-only: latched faults stay)
  NormalModeOnEthernet,  // Ethernet targets: SSLBP normal mode (its start clears faults)
};

// Over the session's card (Registers), or its own SSLBP normal-mode session on the session's
// Ethernet endpoint (NormalModeOnEthernet; register reads on other endpoints). It refuses a
// running host unless the session's options say take over.
std::unique_ptr<LiveSource> make_live_source(Session& session, LiveMode mode);

// How often a card that cannot be read is tried again when samples come every `interval`:
// at the interval, but not more often than timing::kMonitorMinRetry (reopening a vanished
// port or waiting out a timeout at every tick would only spin). `i20 watch` and the console
// both pace their retries by it.
std::chrono::milliseconds retry_interval(std::chrono::milliseconds interval);

// Live readings for a front end that keeps its own pace (the console's live view): one read
// per call. A card that cannot be read has its link dropped, and is tried again only once
// retry_interval() has passed; the calls in between answer with the last error, the card
// untouched.
class LiveSampler {
 public:
  struct Sample {
    std::optional<FaultReadings> readings;  // none: not read; `error` says why
    std::string error;
  };
  LiveSampler(LiveSource& source, std::chrono::milliseconds interval);
  Sample next();

 private:
  using Clock = std::chrono::steady_clock;
  LiveSource& source_;
  std::chrono::milliseconds retry_every_;
  std::optional<Clock::time_point> retry_at_;  // set while the card cannot be read
  std::string error_;
};

// True when the session names an Ethernet target (--eth or an eth:// --port).
bool is_eth_target(const Session& session);

}  // namespace i20::ops
