// SPDX-License-Identifier: GPL-2.0-or-later
// LBP16 over UDP to one card (7I96S/7I92T manuals, "HOST COMMUNICATION", "LBP16").
//
// Rules this client keeps:
// - Replies are accepted only from the card's own IP:port; anything else is ignored.
// - Every packet starts by writing a fresh sequence number to the Scratch register of
//   space 6 (the manual: "Can be used for sequence numbers") and reading it back, so the
//   reply names the packet it answers. Late replies to earlier packets are dropped
//   instead of being taken for the current one, and every packet gets a reply, even one
//   that only writes (the manual asks for a read after writes "for host synchronization").
// - A reply of the wrong size is never acted upon: BadReplyError.
// - A packet that writes WaituS (space 4) gets that much longer to answer: the card holds
//   the reply back by the wait.
// - Only packets without writes are resent after a timeout, unless the caller says the
//   packet is idempotent (Resend::Idempotent). The sequence-number write is not counted:
//   repeating it is harmless by design.
// - How long to wait comes from measured round trips (ReplyTimeout, below), not a fixed
//   figure: a host slowed by load or by sanitizers waits longer, a healthy exchange is not
//   taken for lost. A packet that may not be resent waits, in its one attempt, as long as
//   a resendable one does over all of its attempts.
//
// Not thread-safe: one caller at a time (NormalModeSession hands its client to its
// worker thread and takes it back when the thread has stopped).
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "eth/transport.hpp"

namespace i20::eth {

// The reply timeout from measured round trips, as TCP's retransmission timer (RFC 6298):
// a smoothed round trip and its mean deviation, timeout = smoothed + 4 x deviation, within
// a floor and a ceiling; each timeout doubles it (back-off) until the next measurement.
// Pure: the caller measures and reports; nothing here reads a clock.
class ReplyTimeout {
 public:
  using Duration = std::chrono::microseconds;
  ReplyTimeout(Duration floor, Duration ceiling);

  // A reply arrived `round_trip` after the request it answers was sent.
  void measured(Duration round_trip);
  // An attempt saw no reply in current(): the next waits twice as long (up to the ceiling).
  void timed_out();
  // How long the next attempt waits for its reply (WaituS of the packet not included).
  Duration current() const;
  // The wait of `attempts` attempts in a row, each backed off from the one before: what a
  // packet that is sent once gets, so it is as patient as a resendable one.
  Duration patience(unsigned attempts) const;
  std::optional<Duration> smoothed() const { return smoothed_; }
  Duration floor() const { return floor_; }
  Duration ceiling() const { return ceiling_; }

 private:
  Duration clamp(Duration d) const;
  Duration floor_, ceiling_;
  std::optional<Duration> smoothed_;
  Duration deviation_{0};
  unsigned backoffs_ = 0;
};

struct UdpOptions {
  // The shortest wait for one reply, and the wait before any round trip has been
  // measured. A card on a LAN answers in well under a millisecond; 50 ms leaves room for
  // a busy host without making a dead card slow to report. Measured round trips raise it
  // (ReplyTimeout) up to max_timeout.
  link::Given<std::chrono::milliseconds> timeout;
  // The longest wait for one reply (back-off included): a stalled host gets this much, a
  // dead card costs at most this much per attempt.
  link::Given<std::chrono::milliseconds> max_timeout;
  // Extra attempts for packets that may be resent (see Resend): a transaction is sent at
  // most 1 + retries times. Packets with writes are sent once unless the caller vouches
  // for them (Resend::Idempotent). ops hands down its budget's resends (ops/core/retry.hpp);
  // the passthrough's packets hold writes, so ops' own reads over Ethernet never get
  // resent here.
  link::Given<unsigned> retries;
  // Sequence-number tagging through space 6 Scratch (see above). Off only for cards
  // whose firmware lacks space 6; then stale replies cannot be told apart.
  bool sequence_tags = true;
};

class UdpClient final : public Lbp16Transport {
 public:
  // `ip` must be an IPv4 literal; throws UsageError otherwise. Binds an ephemeral local
  // port, to which the card routes its replies.
  UdpClient(const std::string& ip, std::uint16_t port, UdpOptions options);
  ~UdpClient() override;
  UdpClient(const UdpClient&) = delete;
  UdpClient& operator=(const UdpClient&) = delete;

  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands,
                                   Resend resend = Resend::IfReadOnly) override;
  std::string describe() const override;
  TransportStats stats() const override { return stats_; }

  std::uint16_t local_port() const;
  const UdpOptions& options() const { return options_; }
  const ReplyTimeout& reply_timeout() const { return reply_timeout_; }

  // Space 6 Scratch, where the sequence numbers go.
  static constexpr std::uint16_t kScratchAddress = 0x0018;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  UdpOptions options_;
  ReplyTimeout reply_timeout_;
  TransportStats stats_;
};

}  // namespace i20::eth
