// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/passthrough_link.hpp"

#include "eth/fenced_transport.hpp"

namespace i20::eth {

std::unique_ptr<SslbpPassthroughLink> SslbpPassthroughLink::open(const EthTarget& target,
                                                                 PassthroughOptions options) {
  // Fenced: a request the network delivers late must not run between our later packets.
  return std::make_unique<SslbpPassthroughLink>(
      PassthroughPort::open(target.host_port, target.sserial_port, target.channel_mask(), std::move(options)),
      target);
}

SslbpPassthroughLink::SslbpPassthroughLink(std::shared_ptr<PassthroughPort> port, const EthTarget& target)
    : target_(target), port_(std::move(port)) {}

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
