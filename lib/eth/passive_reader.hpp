// SPDX-License-Identifier: GPL-2.0-or-later
// Reading the 8I20s' process data beside a running host, without touching anything.
//
// While another host (LinuxCNC's hm2_eth) runs an SSERIAL port in normal mode, every one of
// its DOITs leaves each channel's process data in the SSERIAL module's per-channel
// registers (8I20 manual, INTERFACE REGISTERS, 8I20 SPECIFIC INTERFACE REGISTER 0/1
// DEFINITIONS): INTERFACE0 high word = bus voltage in 10 mV, low word = card temperature in
// whole degrees C; INTERFACE1 high word = FAULT, low word = STATUS; CS byte 3 = the remote
// device mode (0x80 for an 8I20) and bytes 1/0 = SSLBP's communication status and errors.
// DATA holds the channel mask of the last DOIT's failures.
//
// A PassiveReader only ever sends LBP16 read commands (no write of any kind: not even the
// space 6 Scratch sequence tag UdpClient uses by default, no DOIT, no start or stop), one
// request per snapshot that reads every channel of every SSERIAL port plus the space 6 UDP
// counters, and never more than `max_requests_per_second` requests (resends included:
// there are none, a lost reply is simply a missed snapshot).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "eth/anything_io.hpp"
#include "eth/batched_opening.hpp"
#include "eth/target.hpp"
#include "eth/transport.hpp"
#include "eth/udp_client.hpp"

namespace i20::eth {

// Spaces requests at least 1 s / rate apart, so no one-second window holds more than
// `rate` of them. Not thread-safe (one reader, one thread).
class RequestPacer {
 public:
  explicit RequestPacer(unsigned per_second);
  // Sleeps until the next request may go, and books it.
  void wait_turn();
  std::chrono::steady_clock::duration spacing() const { return spacing_; }

 private:
  std::chrono::steady_clock::duration spacing_;
  std::optional<std::chrono::steady_clock::time_point> last_{};
};

// One channel's registers as read.
struct ProcessData {
  unsigned port = 0;
  unsigned channel = 0;
  std::uint32_t cs = 0;
  std::uint32_t interface0 = 0;
  std::uint32_t interface1 = 0;
  bool doit_failed = false;  // the port's DATA names this channel

  lbp::hm2::sslbp::ChannelStatus status_register() const { return {cs}; }
  // CS byte 3 says an 8I20 is on the channel (SSLBP fills it once the channel started).
  bool is_8i20() const { return status_register().remote_mode() == lbp::hm2::sslbp::kRemoteMode8i20; }
  // The 8I20 answers the running host's DOITs: an 8I20, communication ready, no failure.
  bool live() const {
    return is_8i20() && (status_register().status() & lbp::hm2::sslbp::ChannelStatus::kNotReady) == 0 &&
           !doit_failed;
  }
  double busv_v() const { return static_cast<double>(interface0 >> 16) * 0.01; }
  // Signed: the manual's "insigned 16 bit" is read as signed (a card below 0 degC).
  int temperature_c() const { return static_cast<std::int16_t>(interface0 & 0xFFFF); }
  std::uint16_t fault() const { return static_cast<std::uint16_t>(interface1 >> 16); }
  std::uint16_t status() const { return static_cast<std::uint16_t>(interface1 & 0xFFFF); }
  bool operator==(const ProcessData&) const = default;
};

struct PassiveSnapshot {
  std::chrono::steady_clock::time_point at{};
  std::chrono::system_clock::time_point wall{};
  std::vector<ProcessData> channels{};  // every channel of every port, port by port
  // Packets the card received and sent since the previous snapshot that were not ours
  // (space 6 RXUDPCount/TXUDPCount): 0 means the running host stopped talking and the
  // registers hold its last cycle. Empty for the first snapshot.
  std::optional<std::uint32_t> foreign_packets{};
};

struct PassiveOptions {
  link::Given<unsigned> max_requests_per_second;
  link::Given<std::chrono::milliseconds> timeout;  // one attempt per request
  // The longest that attempt may wait once measured round trips have raised it.
  link::Given<std::chrono::milliseconds> max_timeout;
};

// The channels SSERIAL port `port` has, from the IDROM pin table (one RX input pin per
// channel); 8 (SSLBP's most) when the table names none. Reading SSLBP's own channel count
// would need a COMMAND write.
unsigned sserial_channels(const HostMot2Info& info, unsigned port);

class PassiveReader {
 public:
  // Opens a UDP socket without sequence tags (those write space 6 Scratch) and surveys the
  // card (identification and IDROM, read-only, one request where the IDROM is where
  // HostMot2 keeps it). Throws DiscoveryError for a card without SSERIAL.
  PassiveReader(const HostPort& host_port, PassiveOptions options);
  // Over any transport (tests); the caller made sure it writes nothing on its own.
  PassiveReader(std::unique_ptr<Lbp16Transport> bus, PassiveOptions options);

  // One request: every port's DATA, every channel's CS, INTERFACE0 and INTERFACE1, and the
  // UDP counters. Waits for its turn under the rate bound first. Throws link::TimeoutError
  // when the reply does not come (nothing is resent).
  PassiveSnapshot read();

  const BoardIdentity& identity() const { return survey_.identity; }
  const HostMot2Info& hostmot2() const { return survey_.hostmot2; }
  const std::vector<SserialPort>& ports() const { return ports_; }
  unsigned channels(unsigned port) const { return channels_.at(port); }
  std::string describe() const { return bus_->describe(); }
  std::uint64_t requests_sent() const { return bus_->stats().packets_sent; }

 private:
  std::unique_ptr<Lbp16Transport> bus_;
  PassiveOptions options_;
  BoardSurvey survey_{};
  std::vector<SserialPort> ports_{};
  std::vector<unsigned> channels_{};
  std::vector<lbp::lbp16::Command> request_{};
  std::optional<std::uint16_t> last_received_{}, last_sent_{};
};

}  // namespace i20::eth
