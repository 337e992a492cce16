// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/udp_client.hpp"

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address_v4.hpp>
#include <boost/asio/ip/udp.hpp>
#include <optional>

#include "eth/errors.hpp"
#include "eth/target.hpp"

namespace i20::eth {

namespace asio = boost::asio;
using asio::ip::udp;
using Clock = std::chrono::steady_clock;
namespace lbp16 = lbp::lbp16;

struct UdpClient::Impl {
  asio::io_context io;
  udp::socket socket{io};
  udp::endpoint card;
  std::string name;
  lbp::Bytes buffer = lbp::Bytes(65536);
  // Starts from the clock so that two clients (or two runs) rarely share numbers.
  std::uint16_t next_tag = static_cast<std::uint16_t>(Clock::now().time_since_epoch().count());

  struct Datagram {
    std::size_t size = 0;
    udp::endpoint sender;
  };

  // Blocks until the socket is readable or the deadline passes.
  void wait_readable(Clock::time_point deadline) {
    bool ready = false;
    socket.async_wait(udp::socket::wait_read, [&](const boost::system::error_code& ec) { ready = !ec; });
    io.restart();
    io.run_until(deadline);
    if (!ready) {
      socket.cancel();
      io.restart();
      io.run();  // lets the cancelled handler finish before its captures go away
    }
  }

  // One datagram, or nullopt when the deadline passes first.
  std::optional<Datagram> receive(Clock::time_point deadline) {
    for (;;) {
      boost::system::error_code ec;
      Datagram d;
      d.size = socket.receive_from(asio::buffer(buffer), d.sender, 0, ec);
      if (!ec) return d;
      if (ec != asio::error::would_block && ec != asio::error::try_again)
        throw link::LinkError("receiving from " + name + " failed: " + ec.message());
      if (Clock::now() >= deadline) return std::nullopt;
      wait_readable(deadline);
    }
  }

  // Drops whatever arrived since the last transaction: late replies to packets that were
  // already given up on.
  std::uint64_t drain() {
    std::uint64_t dropped = 0;
    for (;;) {
      boost::system::error_code ec;
      udp::endpoint sender;
      socket.receive_from(asio::buffer(buffer), sender, 0, ec);
      if (ec) return dropped;
      ++dropped;
    }
  }

  void send(const lbp::Bytes& packet) {
    boost::system::error_code ec;
    socket.send_to(asio::buffer(packet), card, 0, ec);
    if (ec) throw link::LinkError("sending to " + name + " failed: " + ec.message());
  }
};

namespace {

bool has_writes(std::span<const lbp16::Command> commands) {
  return std::any_of(commands.begin(), commands.end(), [](const lbp16::Command& c) { return c.word.write; });
}

// The card holds the reply back by every WaituS in the packet: that time is added to the
// reply timeout, so a packet that waits for an EEPROM write is not taken for lost.
std::chrono::microseconds requested_waits(std::span<const lbp16::Command> commands) {
  std::chrono::microseconds total{0};
  for (const auto& c : commands)
    if (c.word.write && c.word.space == lbp16::space::kTimers && c.address == kWaitMicrosecondsAddress &&
        c.data.size() >= 2)
      total += std::chrono::microseconds(lbp::read_le(lbp::ByteView(c.data).subspan(0, 2)));
  return total;
}

std::vector<lbp16::Command> tagged(std::span<const lbp16::Command> commands, std::uint16_t tag) {
  std::vector<lbp16::Command> packet;
  packet.reserve(commands.size() + 2);
  const lbp::Bytes value = lbp::to_le(tag, 2);
  packet.push_back(
      lbp16::write(lbp16::space::kStatus, UdpClient::kScratchAddress, lbp16::Width::Bits16, value, false));
  packet.push_back(
      lbp16::read(lbp16::space::kStatus, UdpClient::kScratchAddress, lbp16::Width::Bits16, 1, false));
  packet.insert(packet.end(), commands.begin(), commands.end());
  return packet;
}

}  // namespace

UdpClient::UdpClient(const std::string& ip, std::uint16_t port, UdpOptions options)
    : impl_(std::make_unique<Impl>()), options_(options) {
  require_ipv4(ip);
  impl_->card = udp::endpoint(asio::ip::make_address_v4(ip), port);
  impl_->name = HostPort{ip, port}.describe();
  impl_->socket.open(udp::v4());
  impl_->socket.bind(udp::endpoint(udp::v4(), 0));
  impl_->socket.non_blocking(true);
}

UdpClient::~UdpClient() = default;

std::string UdpClient::describe() const {
  return impl_->name;
}

std::uint16_t UdpClient::local_port() const {
  return impl_->socket.local_endpoint().port();
}

std::vector<lbp::Bytes> UdpClient::transact(std::span<const lbp16::Command> commands, Resend resend) {
  const bool writes = has_writes(commands);
  const bool may_resend = resend == Resend::Idempotent || (resend == Resend::IfReadOnly && !writes);
  const unsigned attempts = 1 + (may_resend ? options_.retries : 0);
  const std::size_t prefix = options_.sequence_tags ? 2 : 0;

  std::vector<std::uint16_t> tags;  // of this transaction's attempts: any of them is a valid reply
  const auto foreign_before = stats_.foreign_ignored;
  const auto stale_before = stats_.stale_ignored;
  for (unsigned attempt = 0; attempt < attempts; ++attempt) {
    if (attempt > 0) ++stats_.resends;
    stats_.stale_ignored += impl_->drain();

    const std::uint16_t tag = impl_->next_tag++;
    tags.push_back(tag);
    const std::vector<lbp16::Command> packet =
        options_.sequence_tags ? tagged(commands, tag)
                               : std::vector<lbp16::Command>(commands.begin(), commands.end());
    const lbp::Bytes wire = lbp16::encode_packet(packet);
    const std::size_t expected = lbp16::reply_bytes(packet);
    impl_->send(wire);
    ++stats_.packets_sent;
    if (expected == 0) return std::vector<lbp::Bytes>(commands.size());  // untagged writes: no reply exists

    const auto deadline = Clock::now() + options_.timeout + requested_waits(commands);
    while (auto datagram = impl_->receive(deadline)) {
      if (datagram->sender != impl_->card) {
        ++stats_.foreign_ignored;
        continue;
      }
      const lbp::ByteView reply(impl_->buffer.data(), datagram->size);
      if (options_.sequence_tags && reply.size() >= 2) {
        const auto echoed = static_cast<std::uint16_t>(lbp::read_le(reply.subspan(0, 2)));
        if (std::find(tags.begin(), tags.end(), echoed) == tags.end()) {
          ++stats_.stale_ignored;  // answers a packet we already gave up on
          continue;
        }
      }
      if (reply.size() != expected)
        throw BadReplyError(impl_->name + " answered with " + std::to_string(reply.size()) + " bytes where " +
                            std::to_string(expected) + " were expected; reply ignored");
      ++stats_.replies;
      auto parts = lbp16::split_reply(packet, reply);
      parts.erase(parts.begin(), parts.begin() + static_cast<std::ptrdiff_t>(prefix));
      return parts;
    }
    ++stats_.timeouts;
  }
  std::string message = "no reply from " + impl_->name + " within " +
                        std::to_string(options_.timeout.count()) + " ms (" + std::to_string(attempts) +
                        (attempts == 1 ? " attempt" : " attempts") + ")";
  // What did arrive says where to look: another host or a NAT answering, or a late card.
  if (const auto n = stats_.foreign_ignored - foreign_before; n > 0)
    message += "; ignored " + std::to_string(n) + " datagram" + (n == 1 ? "" : "s") +
               " from another address or port";
  if (const auto n = stats_.stale_ignored - stale_before; n > 0)
    message +=
        "; ignored " + std::to_string(n) + " stale repl" + (n == 1 ? "y" : "ies") + " to earlier packets";
  if (writes && !may_resend)
    message += "; the packet held writes and was not resent, so they may or may not have taken effect";
  throw link::TimeoutError(message);
}

}  // namespace i20::eth
