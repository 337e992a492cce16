// link::Link to one 8I20 behind an Ethernet card, through SSLBP's setup-mode passthrough.
//
// Opening: identify the card (space 7), read the HostMot2 IDROM, locate the SSERIAL port,
// stop it, setup-start the one channel, and check that an 8I20 answered (INTERFACE1 =
// "8I20"). The port stays in setup mode while the link lives; it is stopped (best effort)
// when the link is destroyed. Setup mode drives no motor.
//
// Each LBP command costs one DOIT (see passthrough_plan.hpp for the mapping). One packet
// carries INTERFACE0 (writes), CS, COMMAND = DOIT, a WaituS sized to the expected serial
// time, and the read-back of COMMAND, DATA, INTERFACE0 and CS; when the estimate holds,
// that single round trip completes the command, otherwise read-only polls follow until
// COMMAND clears (deadline: SslbpOptions::command_timeout).
//
// A DATA bit for the channel means the transfer failed: CS is decoded into words and
// raised as link::TimeoutError (timeout bit), link::CrcError (CRC bit) or SslbpError.
// After any failure the next execute() first waits for COMMAND to clear and, if it does
// not, restarts the port in setup mode.
#pragma once

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "eth/card.hpp"
#include "eth/passthrough_plan.hpp"
#include "eth/sslbp_port.hpp"
#include "eth/target.hpp"
#include "eth/transport.hpp"
#include "eth/udp_client.hpp"
#include "link/link.hpp"

namespace i20::eth {

struct PassthroughOptions {
  UdpOptions udp;
  SslbpOptions sslbp;
  // Refuse a channel whose remote is not an 8I20 (INTERFACE1 after setup start).
  bool require_8i20 = true;
  // Added to the serial time estimate of every command: SSLBP's own processing.
  std::chrono::microseconds overhead{60};
  // Character times the remote needs to see a command as complete: an 8I20 in operate
  // mode ends a packet only after a quiet line of its command timeout (25.5 character
  // times as SSLBP sets it; manual, "FRAMING").
  unsigned turnaround_characters = 26;
  // Extra wait for a data write while NV access is EEPROM or flash: a cell write takes
  // milliseconds (docs/facts.md section 7). Underestimating only costs a poll.
  std::chrono::microseconds nv_write_time{5000};
};

// What answered on the channel at setup start.
struct RemoteInfo {
  std::string name{};             // "8I20"
  std::uint32_t unit_number = 0;  // INTERFACE0 after start
  std::uint32_t cs = 0;
};

struct PassthroughStats {
  std::uint64_t commands = 0;         // LBP commands completed
  std::uint64_t round_trips = 0;      // UDP request/reply pairs spent on them
  std::uint64_t max_round_trips = 0;  // of any single command
  std::uint64_t restarts = 0;         // setup restarts after errors
};

class SslbpPassthroughLink final : public link::Link {
 public:
  // Opens UDP to target.card and sets the channel up. Throws DiscoveryError (not a
  // HostMot2 card, no SSERIAL port, no 8I20 on the channel) or link::LinkError.
  static std::unique_ptr<SslbpPassthroughLink> open(const EthTarget& target, PassthroughOptions options = {});

  // The same over any transport (tests inject faults here).
  SslbpPassthroughLink(std::unique_ptr<Lbp16Transport> bus, const EthTarget& target,
                       PassthroughOptions options = {});
  ~SslbpPassthroughLink() override;

  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override;
  std::string describe() const override { return target_.describe(); }
  // INTERFACE0 is 32 bits wide: no 8-byte accesses through the passthrough.
  std::size_t max_data_bytes() const override { return 4; }
  std::vector<std::string> notes() const override { return notes_; }

  const RemoteInfo& remote() const { return remote_; }
  const CardIdentity& card() const { return card_; }
  const SslbpParameters& sslbp_parameters() const { return parameters_; }
  const PassthroughStats& stats() const { return stats_; }
  TransportStats transport_stats() const { return bus_->stats(); }
  // Estimated serial time of a step, the WaituS the link asks for.
  std::chrono::microseconds settle_for(const PassthroughStep& step) const;

 private:
  void start_setup();
  void resync();
  Completion execute_step(const PassthroughStep& step, std::size_t index);
  [[noreturn]] void raise_transfer_error(const lbp::Command& command, std::uint32_t cs,
                                         std::size_t index) const;

  std::unique_ptr<Lbp16Transport> bus_;
  EthTarget target_;
  PassthroughOptions options_;
  CardIdentity card_{};
  std::unique_ptr<SslbpPort> port_;
  SslbpParameters parameters_{};
  std::uint32_t baud_ = 0;
  RemoteInfo remote_;
  std::vector<std::string> notes_{};
  PassthroughStats stats_;
  std::uint8_t nv_mode_ = 0;
  bool needs_resync_ = false;
};

}  // namespace i20::eth
