// SPDX-License-Identifier: GPL-2.0-or-later
// "What is on this card?": card name and versions, HostMot2 board, SSERIAL ports and
// which channels have an 8I20 answering. For the CLI's scan command; prints nothing.
//
// First the running-host check (running_host.hpp) over every SSERIAL port: scanning stops
// the ports, so while another host runs the card it is refused (RunningHostError) unless
// options.running_host.take_over. Then each port is stopped, setup-started on all of its
// channels at once (DATA names the channels that failed), read back (CS, unit number,
// card name) and stopped again.
//
// Each 8I20 is also given the name LinuxCNC's hostmot2 driver uses for it,
// hm2_<board>.<board index>.8i20.<port>.<channel> (hostmot2(9) manual page, option
// use_serial_numbers: "hm2_5i23.0.8i20.0.1.current"; sserial(9)). <board> is the card name
// from LBP16 space 7 in lower case, as hm2_eth names Ethernet cards ("hm2_7i96s.0");
// <board index> counts the cards of that name in hm2_eth's board_ip list, so it is
// ScanOptions::board_index, 0 for a machine with one card.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "eth/anything_io.hpp"
#include "eth/running_host.hpp"
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
  std::string status{};         // CS in words ("ok", "communication not ready, timeout")
  std::string linuxcnc_name{};  // "hm2_7i96s.0.8i20.0.0" for an 8I20, else empty

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
  BoardIdentity card{};
  std::string config_name{};  // "HOSTMOT2"
  std::string board_name{};   // from the IDROM
  std::uint32_t clock_low_hz = 0;
  std::vector<PortReport> ports{};
  HostActivity host_activity{};  // what the running-host check saw before the first stop
  // Packets of another host that reached the card while we scanned (after a take-over):
  // its DOITs may have changed what the channels reported.
  std::uint32_t foreign_packets_during_scan = 0;

  // Every channel with an 8I20, as targets the other commands accept.
  std::vector<EthTarget> targets() const;
};

struct ScanOptions {
  UdpOptions udp;
  SslbpOptions sslbp;
  RunningHostCheck running_host;
  unsigned board_index = 0;  // for the LinuxCNC names
};

// "hm2_7i96s.0.8i20.0.3": the LinuxCNC hostmot2 name of a smart-serial remote.
std::string linuxcnc_device_name(std::string_view card_name, unsigned board_index, unsigned sserial_port,
                                 unsigned channel, std::string_view remote = "8i20");

ScanResult scan(const HostPort& host_port, ScanOptions options);
ScanResult scan(const std::string& ip, ScanOptions options);
// Over any transport.
ScanResult scan(Lbp16Transport& bus, ScanOptions options);

}  // namespace i20::eth
