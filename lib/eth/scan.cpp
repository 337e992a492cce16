// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/scan.hpp"

#include <algorithm>
#include <cctype>

namespace i20::eth {
namespace {

std::string lower(std::string_view text) {
  std::string out(text);
  std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
  return out;
}

PortReport scan_port(Lbp16Transport& bus, const SserialPort& port, bool timer_space,
                     const ScanOptions& options, const std::string& card_name) {
  SslbpPort sslbp(bus, port, timer_space, options.sslbp);
  PortReport report{.index = port.index, .gtag = port.gtag, .command_address = port.registers.command};
  sslbp.stop_all();
  report.parameters = sslbp.read_parameters();
  const unsigned count = std::min<unsigned>(report.parameters.channels, lbp::hm2::kMaxChannelsPerPort);
  if (count == 0) return report;
  const auto mask = static_cast<std::uint8_t>((1u << count) - 1);
  const std::uint8_t failed = sslbp.start_setup(mask, options.running_host.setup_start_attempts());
  const auto regs = sslbp.read_channels(mask);
  for (unsigned ch = 0; ch < count; ++ch) {
    const ChannelRegisters& r = regs[ch];
    const bool answered = (failed & (1u << ch)) == 0;
    report.channels.push_back(ChannelReport{.channel = ch,
                                            .answered = answered,
                                            .device_name = answered ? r.name() : std::string(),
                                            .unit_number = answered ? r.interface0 : 0,
                                            .cs = r.cs,
                                            .status = r.status().describe()});
    if (report.channels.back().is_8i20())
      report.channels.back().linuxcnc_name =
          linuxcnc_device_name(card_name, options.board_index, port.index, ch);
  }
  sslbp.stop_all();
  return report;
}

}  // namespace

std::string linuxcnc_device_name(std::string_view card_name, unsigned board_index, unsigned sserial_port,
                                 unsigned channel, std::string_view remote) {
  // hm2_eth names a 7I92T like the 7I92 (docs/linuxcnc-hal.md), as `i20 hal` writes it.
  std::string board = lower(card_name);
  if (board == "7i92t") board = "7i92";
  return "hm2_" + board + "." + std::to_string(board_index) + "." + lower(remote) + "." +
         std::to_string(sserial_port) + "." + std::to_string(channel);
}

std::vector<EthTarget> ScanResult::targets() const {
  std::vector<EthTarget> out;
  for (const auto& port : ports)
    for (const auto& ch : port.channels)
      if (ch.is_8i20())
        out.push_back(
            EthTarget{.host_port = card_address, .sserial_port = port.index, .channel = ch.channel});
  return out;
}

ScanResult scan(Lbp16Transport& bus, ScanOptions options) {
  ScanResult result;
  result.card = identify(bus);
  const HostMot2Info info = read_hostmot2(bus);
  result.config_name = info.ident.config_name;
  result.board_name = info.idrom.board_name;
  result.clock_low_hz = info.idrom.clock_low;
  const auto ports = info.sserial_ports();
  if (!ports.empty())
    result.host_activity =
        require_no_running_host(bus, ports, options.running_host, "stop and scan the SSERIAL ports");
  for (const SserialPort& port : ports)
    result.ports.push_back(
        scan_port(bus, port, result.card.has_timer_space(), options, result.card.card_name));
  if (!ports.empty())
    result.foreign_packets_during_scan =
        foreign_packets_since(bus, result.host_activity, options.running_host);
  return result;
}

ScanResult scan(const HostPort& host_port, ScanOptions options) {
  UdpClient bus(host_port.ip, host_port.port, options.udp);
  ScanResult result = scan(bus, options);
  result.card_address = host_port;
  return result;
}

ScanResult scan(const std::string& ip, ScanOptions options) {
  return scan(parse_host_port(ip), options);
}

}  // namespace i20::eth
