// "What is on this card?": card name and versions, HostMot2 board, SSERIAL ports and
// which channels have an 8I20 answering. For the CLI's scan command; prints nothing.
//
// Each port is stopped, setup-started on all of its channels at once (DATA names the
// channels that failed), read back (CS, unit number, card name) and stopped again.
// Scanning interrupts whatever the port was doing (LinuxCNC must not be running).
#pragma once

#include <string>
#include <vector>

#include "eth/card.hpp"
#include "eth/sslbp_port.hpp"
#include "eth/target.hpp"
#include "eth/udp_client.hpp"

namespace i20::eth {

struct ChannelReport {
  unsigned channel = 0;
  bool answered = false;          // setup start succeeded on this channel
  std::string device_name{};      // INTERFACE1 as text: "8I20"
  std::uint32_t unit_number = 0;  // INTERFACE0
  std::uint32_t cs = 0;
  std::string status{};  // CS in words ("ok", "communication not ready, timeout")

  bool is_8i20() const { return answered && device_name == "8I20"; }
};

struct PortReport {
  unsigned index = 0;
  std::uint8_t gtag = 0;
  std::uint16_t command_address = 0;
  SslbpParameters parameters{};
  std::vector<ChannelReport> channels{};
};

struct ScanResult {
  HostPort card_address{};
  CardIdentity card{};
  std::string config_name{};  // "HOSTMOT2"
  std::string board_name{};   // from the IDROM
  std::uint32_t clock_low_hz = 0;
  std::vector<PortReport> ports{};

  // Every channel with an 8I20, as targets the other commands accept.
  std::vector<EthTarget> targets() const;
};

struct ScanOptions {
  UdpOptions udp;
  SslbpOptions sslbp;
};

ScanResult scan(const HostPort& card, ScanOptions options = {});
ScanResult scan(const std::string& ip, ScanOptions options = {});
// Over any transport.
ScanResult scan(Lbp16Transport& bus, ScanOptions options = {});

}  // namespace i20::eth
