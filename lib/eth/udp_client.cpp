// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/udp_client.hpp"

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address_v4.hpp>
#include <boost/asio/ip/udp.hpp>
#include <deque>
#include <optional>

#include "eth/errors.hpp"
#include "eth/target.hpp"
#include "link/wait_bound.hpp"

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

  // Tags of the latest answered packets: a reply to one of them again is a copy of our
  // request that the network delivered twice.
  std::deque<std::uint16_t> answered;
  void remember_answered(std::uint16_t tag) {
    answered.push_back(tag);
    if (answered.size() > 256) answered.pop_front();
  }
  bool was_answered(lbp::ByteView reply) const {
    if (reply.size() < 2) return false;
    const auto tag = static_cast<std::uint16_t>(lbp::read_le(reply.subspan(0, 2)));
    return std::find(answered.begin(), answered.end(), tag) != answered.end();
  }

  // Drops whatever arrived since the last transaction: late replies to packets that were
  // already given up on (stale), or second replies to repeated copies of ours (repeats).
  void drain(bool tagged, TransportStats& stats) {
    for (;;) {
      boost::system::error_code ec;
      udp::endpoint sender;
      const std::size_t size = socket.receive_from(asio::buffer(buffer), sender, 0, ec);
      if (ec) return;
      if (tagged && sender == card && was_answered(lbp::ByteView(buffer.data(), size)))
        ++stats.network_repeats;
      else
        ++stats.stale_ignored;
    }
  }

  void send(const lbp::Bytes& packet) {
    boost::system::error_code ec;
    socket.send_to(asio::buffer(packet), card, 0, ec);
    if (ec == boost::system::errc::operation_not_permitted)
      throw link::LinkError("sending to " + name + " was refused by this host's firewall (" + ec.message() +
                            "): on a host running LinuxCNC, hm2_eth lets only itself reach the card; "
                            "run this from another computer on the card's network, or stop LinuxCNC");
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

std::string milliseconds_text(std::chrono::microseconds d) {
  return std::to_string((d.count() + 999) / 1000) + " ms";
}

}  // namespace

ReplyTimeout::ReplyTimeout(Duration floor, Duration ceiling)
    : floor_(std::max(floor, Duration{1})), ceiling_(std::max(ceiling, floor_)) {}

ReplyTimeout::Duration ReplyTimeout::clamp(Duration d) const {
  return std::clamp(d, floor_, ceiling_);
}

void ReplyTimeout::measured(Duration round_trip) {
  round_trip = std::max(round_trip, Duration{0});
  if (!smoothed_) {
    smoothed_ = round_trip;  // RFC 6298 2.2
    deviation_ = round_trip / 2;
  } else {
    const Duration error = *smoothed_ > round_trip ? *smoothed_ - round_trip : round_trip - *smoothed_;
    deviation_ = (3 * deviation_ + error) / 4;  // RFC 6298 2.3: beta 1/4, alpha 1/8
    smoothed_ = (7 * *smoothed_ + round_trip) / 8;
  }
  backoffs_ = 0;  // a measurement replaces the backed-off value (RFC 6298 5.7)
}

void ReplyTimeout::timed_out() {
  if (current() < ceiling_) ++backoffs_;
}

ReplyTimeout::Duration ReplyTimeout::current() const {
  // RFC 6298 2.3: at least one clock tick above the mean, so a reply exactly as slow as the
  // steady mean still fits; a millisecond, about what a busy host delays a thread by.
  Duration d = smoothed_ ? clamp(*smoothed_ + std::max(4 * deviation_, Duration{1000})) : floor_;
  for (unsigned i = 0; i < backoffs_ && d < ceiling_; ++i) d = clamp(2 * d);
  return d;
}

ReplyTimeout::Duration ReplyTimeout::patience(unsigned attempts) const {
  Duration total{0};
  Duration d = current();
  for (unsigned i = 0; i < attempts; ++i, d = clamp(2 * d)) total += d;
  return total;
}

UdpClient::UdpClient(const std::string& ip, std::uint16_t port, UdpOptions options)
    : impl_(std::make_unique<Impl>()),
      options_(options),
      reply_timeout_(options.timeout, options.max_timeout) {
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
  const unsigned attempts = 1 + (may_resend ? options_.retries.get() : 0u);
  const std::size_t prefix = options_.sequence_tags ? 2 : 0;

  std::vector<std::uint16_t> tags;         // of this transaction's attempts: any of them is a valid reply
  std::vector<Clock::time_point> sent_at;  // of each attempt, for the round trip of its reply
  const auto foreign_before = stats_.foreign_ignored;
  // Replies to earlier packets: late ones, and second replies to copies of ours.
  const auto stale_before = stats_.stale_ignored + stats_.network_repeats;
  const auto held_back = requested_waits(commands);
  std::chrono::microseconds waited{0};
  for (unsigned attempt = 0; attempt < attempts; ++attempt) {
    // Past the operation's end nothing more is sent: not this packet, nor a resend of it.
    if (attempt == 0) link::WaitBound::require_time_left(impl_->name);
    if (link::WaitBound::expired()) break;
    if (attempt > 0) ++stats_.resends;
    // Late replies to earlier transactions go. Between attempts of this one, a tagged reply
    // to an earlier attempt is still the answer (the tag says so): keep it.
    if (attempt == 0 || !options_.sequence_tags) impl_->drain(options_.sequence_tags, stats_);

    const std::uint16_t tag = impl_->next_tag++;
    tags.push_back(tag);
    const std::vector<lbp16::Command> packet =
        options_.sequence_tags ? tagged(commands, tag)
                               : std::vector<lbp16::Command>(commands.begin(), commands.end());
    const lbp::Bytes wire = lbp16::encode_packet(packet);
    const std::size_t expected = lbp16::reply_bytes(packet);
    // Timed from before the send: a reply cannot come before it, and a send (or a thread put
    // aside just after it) that takes milliseconds on a loaded host must not shorten the round
    // trip learnt (the sanitizer run saw 37.6 ms learnt for a card answering after 40 ms).
    sent_at.push_back(Clock::now());
    impl_->send(wire);
    ++stats_.packets_sent;
    if (expected == 0) return std::vector<lbp::Bytes>(commands.size());  // untagged writes: no reply exists

    // A packet sent once waits as long as a resendable one over all its attempts.
    const auto wait =
        (may_resend ? reply_timeout_.current() : reply_timeout_.patience(1 + options_.retries)) + held_back;
    // Never past the operation's end: a packet sent once would otherwise wait out all its
    // attempts however little of the command's time is left.
    const auto waits = std::chrono::duration_cast<std::chrono::microseconds>(link::WaitBound::cap(wait));
    const auto deadline = sent_at.back() + waits;
    while (auto datagram = impl_->receive(deadline)) {
      if (datagram->sender != impl_->card) {
        ++stats_.foreign_ignored;
        continue;
      }
      const lbp::ByteView reply(impl_->buffer.data(), datagram->size);
      // Which attempt the reply answers: its echoed tag, or (untagged) only a first attempt.
      std::optional<std::size_t> answers;
      if (!options_.sequence_tags) {
        if (attempt == 0) answers = 0;
      } else if (reply.size() >= 2) {
        const auto echoed = static_cast<std::uint16_t>(lbp::read_le(reply.subspan(0, 2)));
        const auto it = std::find(tags.begin(), tags.end(), echoed);
        if (it == tags.end()) {
          // Answers a packet we already gave up on, or a copy of one already answered.
          ++(impl_->was_answered(reply) ? stats_.network_repeats : stats_.stale_ignored);
          continue;
        }
        answers = static_cast<std::size_t>(it - tags.begin());
      }
      if (reply.size() != expected)
        throw BadReplyError(impl_->name + " answered with " + std::to_string(reply.size()) + " bytes where " +
                            std::to_string(expected) + " were expected; reply ignored");
      ++stats_.replies;
      if (options_.sequence_tags) impl_->remember_answered(tags[answers.value_or(0)]);
      if (answers)
        reply_timeout_.measured(
            std::chrono::duration_cast<std::chrono::microseconds>(Clock::now() - sent_at[*answers]) -
            held_back);
      auto parts = lbp16::split_reply(packet, reply);
      parts.erase(parts.begin(), parts.begin() + static_cast<std::ptrdiff_t>(prefix));
      return parts;
    }
    ++stats_.timeouts;
    reply_timeout_.timed_out();
    waited += waits;
  }
  std::string message = "no reply from " + impl_->name + " within " + milliseconds_text(waited) + " (" +
                        std::to_string(attempts) + (attempts == 1 ? " attempt" : " attempts") + ")";
  // What did arrive says where to look: another host or a NAT answering, or a late card.
  if (const auto n = stats_.foreign_ignored - foreign_before; n > 0)
    message += "; ignored " + std::to_string(n) + " datagram" + (n == 1 ? "" : "s") +
               " from another address or port";
  if (const auto n = stats_.stale_ignored + stats_.network_repeats - stale_before; n > 0)
    message +=
        "; ignored " + std::to_string(n) + " stale repl" + (n == 1 ? "y" : "ies") + " to earlier packets";
  if (writes && !may_resend)
    message += "; the packet held writes and was not resent, so they may or may not have taken effect";
  throw link::TimeoutError(message);
}

}  // namespace i20::eth
