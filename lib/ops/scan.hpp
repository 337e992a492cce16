// SPDX-License-Identifier: GPL-2.0-or-later
// The Ethernet card as a whole, for `i20 scan` and the passive monitor: which card the
// global flags name, and the scan of its SSERIAL ports and channels (which 8I20s answer,
// their eth:// targets and LinuxCNC names). The eth types are named here so no app
// includes lib/eth.
#pragma once

#include <string>

#include "eth/scan.hpp"
#include "eth/target.hpp"
#include "ops/core/endpoint.hpp"

namespace i20::ops {

using eth::EthTarget;
using eth::HostPort;
using eth::ScanResult;

// The Ethernet card the flags name: --eth IP[:UDPPORT] or an eth:// URL (in --eth or in
// --port); nullopt when they name none. UsageError for an address that does not parse.
std::optional<HostPort> ethernet_host_port(const TargetFlags& target);

struct ScanRun {
  ScanResult result;
  // --take-over was given and another host was running the card: its SSERIAL ports were
  // stopped under it (its axes dropped out).
  bool stopped_running_host = false;
};

// Scans the card. Refuses (RunningHostError) while another host runs it, unless
// `link.take_over`. The reply timeout is the link's.
ScanRun scan_host_port(const HostPort& host_port, const LinkSettings& link);

}  // namespace i20::ops
