// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 report`: everything a forum post or a support call needs about one card, gathered
// read-only in one place: identity, firmware and whether its map is confirmed, every
// parameter (a fact, or unknown and why), which NV values are not live yet, FAULT/STATUS,
// the LBP status and CRC error count, and the link's statistics.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "ops/core/amp.hpp"
#include "ops/faults.hpp"
#include "ops/core/read.hpp"
#include "profile/profile.hpp"

namespace i20::ops {

struct LinkFigures {
  std::uint64_t exchanges = 0, commands = 0, bytes_sent = 0, bytes_received = 0;
  std::uint64_t timeouts = 0, crc_errors = 0, framing_errors = 0, resyncs = 0;
};

struct ServiceReport {
  std::chrono::system_clock::time_point when;
  std::string target;  // as the user named it
  Identity identity;
  std::vector<Reading> values;        // every parameter the database places
  std::vector<std::string> not_live;  // NV cells whose working twin holds something else
  std::optional<FaultReadings> faults;
  std::string faults_error;             // why FAULT/STATUS could not be read as facts
  std::optional<LinkFigures> link;      // the serial/simulator link's counters, when it has them
  std::size_t retries = 0;              // reads repeated after lost or garbled replies
  std::vector<std::string> link_notes;  // what the transport found out (adapter latency, ...)
};

// Reads only. Ctrl-C stops it (Cancelled).
ServiceReport gather_report(Amp& amp, std::chrono::system_clock::time_point when);

// The report's NV setup as a profile (the writable EEPROM parameters whose values are facts),
// so `i20 profile apply REPORT` writes a card back to what the report saw.
profile::Profile report_profile(const ServiceReport& report, const params::ParamDb& db);

}  // namespace i20::ops
