// SPDX-License-Identifier: GPL-2.0-or-later
// link::Link to one 8I20 behind an Ethernet card, through SSLBP's setup-mode passthrough:
// a PassthroughPort (passthrough_port.hpp) of the target's SSERIAL port with only the
// target's channel, which it owns. Opening refuses with RunningHostError when another
// host runs the card (unless options.running_host.take_over), because setting a port up
// stops it. Setup mode drives no motor and clears nothing: reading through this link
// leaves latched faults as they are.
//
// One execute() is as few UDP packets as the batch allows: usually one round trip for a
// dump, two for an NV write with its verify. A DATA bit for the channel means the
// transfer failed: CS is decoded into words and raised as link::TimeoutError (timeout
// bit), link::CrcError (CRC bit) or SslbpError. After any failure the next execute()
// first waits for COMMAND to clear and, if it does not, restarts the port in setup mode.
//
// For several channels of one port (a fleet), open a PassthroughPort with their mask and
// use PassthroughPort::link(channel) for each instead: their commands then share DOITs.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "eth/passthrough_port.hpp"

namespace i20::eth {

class SslbpPassthroughLink final : public link::Link {
 public:
  // Opens UDP to target.host_port and sets the channel up. Throws RunningHostError,
  // DiscoveryError (not a HostMot2 card, no SSERIAL port, no 8I20 on the channel) or
  // link::LinkError.
  static std::unique_ptr<SslbpPassthroughLink> open(const EthTarget& target, PassthroughOptions options);

  // The same over any transport (tests inject faults here).
  SslbpPassthroughLink(std::unique_ptr<Lbp16Transport> bus, const EthTarget& target,
                       PassthroughOptions options);
  // Over a port already opened for target's channel.
  SslbpPassthroughLink(std::shared_ptr<PassthroughPort> port, const EthTarget& target);

  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override;
  std::string describe() const override { return target_.describe(); }
  // INTERFACE0 is 32 bits wide: no 8-byte accesses through the passthrough.
  std::size_t max_data_bytes() const override { return 4; }
  std::vector<std::string> notes() const override { return port_->notes(); }

  const RemoteInfo& remote() const { return port_->remote(target_.channel); }
  const BoardIdentity& board() const { return port_->board(); }
  const SslbpParameters& sslbp_parameters() const { return port_->sslbp_parameters(); }
  PassthroughStats stats() const { return port_->stats(); }
  TransportStats transport_stats() const { return port_->transport_stats(); }
  PassthroughPort& port() { return *port_; }
  // Estimated time of one DOIT of `step`, the WaituS the link asks for (NV mode as known).
  std::chrono::microseconds settle_for(const PassthroughStep& step) const {
    return port_->settle_for(step, target_.channel, std::uint8_t{0});
  }

 private:
  EthTarget target_;
  std::shared_ptr<PassthroughPort> port_;
};

}  // namespace i20::eth
