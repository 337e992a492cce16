// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/passthrough_link.hpp"

#include "eth/fenced_transport.hpp"

namespace i20::eth {

std::unique_ptr<SslbpPassthroughLink> SslbpPassthroughLink::open(const EthTarget& target,
                                                                 PassthroughOptions options) {
  // Fenced: a request the network delivers late must not run between our later packets.
  auto bus = std::make_unique<FencedTransport>(
      std::make_unique<UdpClient>(target.host_port.ip, target.host_port.port, options.udp), options.fence);
  return std::make_unique<SslbpPassthroughLink>(std::move(bus), target, std::move(options));
}

SslbpPassthroughLink::SslbpPassthroughLink(std::unique_ptr<Lbp16Transport> bus, const EthTarget& target,
                                           PassthroughOptions options)
    : target_(target),
      port_(std::make_shared<PassthroughPort>(std::move(bus), target.sserial_port, target.channel_mask(),
                                              std::move(options))) {}

std::vector<lbp::Bytes> SslbpPassthroughLink::execute(std::span<const lbp::Command> batch) {
  const PassthroughPort::Batch one{.channel = target_.channel, .commands = batch};
  auto outcome = std::move(port_->execute(std::span(&one, 1)).front());
  if (outcome.error) std::rethrow_exception(outcome.error);
  return std::move(outcome.replies);
}

}  // namespace i20::eth
