// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/scan.hpp"

#include "eth/running_host.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {

std::optional<HostPort> ethernet_host_port(const TargetFlags& target) {
  const std::string text =
      !target.eth.empty() ? target.eth : (eth::is_eth_url(target.port) ? target.port : std::string());
  if (text.empty()) return std::nullopt;
  return eth::is_eth_url(text) ? eth::parse_target(text).host_port : eth::parse_host_port(text);
}

ScanRun scan_host_port(const HostPort& host_port, const LinkSettings& link) {
  const eth::ScanOptions options = timing::scan(link);
  ScanRun run{eth::scan(host_port, options)};
  run.stopped_running_host =
      link.take_over && eth::host_is_running(run.result.host_activity, options.running_host);
  return run;
}

}  // namespace i20::ops
