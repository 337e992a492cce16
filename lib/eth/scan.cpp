#include "eth/scan.hpp"

#include <algorithm>

namespace i20::eth {
namespace {

PortReport scan_port(Lbp16Transport& bus, const SserialPort& port, bool timer_space,
                     const SslbpOptions& options) {
  SslbpPort sslbp(bus, port, timer_space, options);
  PortReport report{.index = port.index, .gtag = port.gtag, .command_address = port.registers.command};
  sslbp.stop_all();
  report.parameters = sslbp.read_parameters();
  const unsigned count = std::min<unsigned>(report.parameters.channels, lbp::hm2::kMaxChannelsPerPort);
  if (count == 0) return report;
  const auto mask = static_cast<std::uint8_t>((1u << count) - 1);
  const std::uint8_t failed = sslbp.start_setup(mask);
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
  }
  sslbp.stop_all();
  return report;
}

}  // namespace

std::vector<EthTarget> ScanResult::targets() const {
  std::vector<EthTarget> out;
  for (const auto& port : ports)
    for (const auto& ch : port.channels)
      if (ch.is_8i20())
        out.push_back(EthTarget{.card = card_address, .sserial_port = port.index, .channel = ch.channel});
  return out;
}

ScanResult scan(Lbp16Transport& bus, ScanOptions options) {
  ScanResult result;
  result.card = identify(bus);
  const HostMot2Info info = read_hostmot2(bus);
  result.config_name = info.ident.config_name;
  result.board_name = info.idrom.board_name;
  result.clock_low_hz = info.idrom.clock_low;
  for (const SserialPort& port : info.sserial_ports())
    result.ports.push_back(scan_port(bus, port, result.card.has_timer_space(), options.sslbp));
  return result;
}

ScanResult scan(const HostPort& card, ScanOptions options) {
  UdpClient bus(card.ip, card.port, options.udp);
  ScanResult result = scan(bus, options);
  result.card_address = card;
  return result;
}

ScanResult scan(const std::string& ip, ScanOptions options) {
  return scan(parse_host_port(ip), options);
}

}  // namespace i20::eth
