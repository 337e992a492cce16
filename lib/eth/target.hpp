// SPDX-License-Identifier: GPL-2.0-or-later
// Where an 8I20 sits behind an Ethernet card, as the CLI names it.
//
// URL form (one argument, works wherever a serial device path is accepted):
//
//   eth://IP[:UDPPORT][/portP][/chN]
//
//   eth://192.168.1.121/ch0          7I96S: its one SSERIAL port, channel 0
//   eth://192.168.1.121              the same (port 0, channel 0 are the defaults)
//   eth://10.10.10.10/port1/ch5      7I92T: second SSERIAL instance, channel 5
//   eth://127.0.0.1:40000/ch0        a virtual card on another UDP port
//
// Flag form: --eth IP[:UDPPORT] --channel N [--sserial-port P], built with make_target().
// IP must be an IPv4 literal (the cards have no DNS names). "port" in the path is the
// SSERIAL instance; the UDP port only ever follows the colon.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "lbp16/lbp16.hpp"

namespace i20::eth {

inline constexpr unsigned kMaxSserialPorts = 4;
inline constexpr unsigned kMaxChannels = 8;  // SSLBP channel masks are 8 bits

struct HostPort {
  std::string ip{};
  std::uint16_t port = lbp::lbp16::kUdpPort;

  // "192.168.1.121", or "127.0.0.1:40000" when the port is not 27181.
  std::string describe() const;
  bool operator==(const HostPort&) const = default;
};

// "IP[:PORT]". Throws UsageError naming the bad part.
HostPort parse_host_port(std::string_view text, std::uint16_t default_port = lbp::lbp16::kUdpPort);

// Throws UsageError unless `text` is a dotted IPv4 address.
void require_ipv4(std::string_view text);

struct EthTarget {
  HostPort host_port{};
  unsigned sserial_port = 0;
  unsigned channel = 0;

  // "eth 192.168.1.121 ch 0", "eth 10.0.0.2 port 1 ch 5": for Link::describe().
  std::string describe() const;
  // The canonical URL, parse_target(url()) == *this.
  std::string url() const;
  std::uint8_t channel_mask() const { return static_cast<std::uint8_t>(1u << channel); }
  bool operator==(const EthTarget&) const = default;
};

// True for strings that start with "eth://": lets the CLI route a target argument.
bool is_eth_url(std::string_view text);

// Throws UsageError with the expected syntax on anything malformed.
EthTarget parse_target(std::string_view url);

// The flag form. Throws UsageError on a bad address or an out-of-range channel/port.
EthTarget make_target(std::string_view host_port, unsigned channel, unsigned sserial_port = 0);

}  // namespace i20::eth
