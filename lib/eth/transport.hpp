// SPDX-License-Identifier: GPL-2.0-or-later
// The seam between the LBP16 users (discovery, SSLBP, passthrough, normal mode) and the
// UDP socket: "send these LBP16 commands as one packet, give me each read's data".
// Tests put fault-injecting transports here; production uses UdpClient.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "lbp16/lbp16.hpp"
#include "link/given.hpp"

namespace i20::eth {

// Whether a packet may be sent again when its reply does not come back. LBP16 has no
// acknowledgement other than the reply, so a lost reply leaves a write's fate unknown.
enum class Resend {
  IfReadOnly,  // default: resend only packets without writes
  Idempotent,  // the caller vouches that executing the packet twice is harmless
  Never,       // one attempt, even for reads (periodic traffic that the next cycle replaces)
};

struct TransportStats {
  std::uint64_t packets_sent = 0;  // every send, resends included
  std::uint64_t replies = 0;       // accepted replies
  std::uint64_t resends = 0;
  std::uint64_t timeouts = 0;         // attempts that saw no acceptable reply in time
  std::uint64_t foreign_ignored = 0;  // datagrams from another address or port
  std::uint64_t stale_ignored = 0;    // late replies to earlier packets
  // Requests of ours that the network delivered twice: a second reply to a packet already
  // answered (its sequence tag). The card counted each copy as a packet received and sent.
  std::uint64_t network_repeats = 0;
  // FencedTransport (fenced_transport.hpp):
  std::uint64_t late_arrivals = 0;     // packets of ours the card received after a later one
  std::uint64_t foreign_arrivals = 0;  // packets the card received that were not ours
  std::uint64_t fences = 0;            // waits for unanswered writing packets to arrive
  std::uint64_t lost_writers = 0;      // writing packets that had not arrived by a fence's bound
  // Packets of ours the card had not counted at our last answered packet: late ones (a
  // request the network delayed past its resend) may still arrive, and are not another host's.
  std::uint64_t unarrived = 0;
  // Packets of ours that reached (or may reach) the card: every send and every copy the
  // network made of one. What a check for another host's packets counts as ours.
  std::uint64_t ours() const { return packets_sent + network_repeats; }
};

// What a fence found (Lbp16Transport::fence()).
struct FenceReport {
  bool needed = false;        // a writing packet of ours might still have been on its way
  bool all_arrived = true;    // the card's count shows every packet of ours arrived
  std::uint64_t missing = 0;  // packets of ours not arrived by the bound (taken as lost)
  std::chrono::milliseconds waited{0};
};

// Space 4 WaituS (7I96S/7I92T manuals, "SPACE 4 LBP TIMER/UTILITY AREA"): writing it
// delays the card's processing of the rest of the packet by that many microseconds
// (0..65535), so the reply comes that much later.
inline constexpr std::uint16_t kWaitMicrosecondsAddress = 0x0002;

// Space 6 counters (7I96S and 7I92T manuals, "SPACE 6 LBP STATUS/CONTROL AREA"): the UDP
// packets the card received and sent, 16 bits each, wrapping.
inline constexpr std::uint16_t kRxUdpCountAddress = 0x000A;
inline constexpr std::uint16_t kTxUdpCountAddress = 0x0010;

// The read of RXUDPCount alone, for a packet that must tell whether another packet reached
// the card since an earlier one.
inline lbp::lbp16::Command received_count_read() {
  return lbp::lbp16::read(lbp::lbp16::space::kStatus, kRxUdpCountAddress, lbp::lbp16::Width::Bits16);
}

class Lbp16Transport {
 public:
  virtual ~Lbp16Transport() = default;

  // Sends the commands as one packet and returns the data of each (empty for writes).
  // Throws link::TimeoutError when no reply comes back, eth::BadReplyError when the reply
  // has the wrong size.
  virtual std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands,
                                           Resend resend = Resend::IfReadOnly) = 0;

  // transact(), and how many packets this transport had sent once this one was (its own
  // included, resends too), counted together with it even when other threads share the
  // transport: what a check for another host's packets compares the card's count with.
  virtual std::vector<lbp::Bytes> transact_counted(std::span<const lbp::lbp16::Command> commands,
                                                   Resend resend, std::uint64_t& sent) {
    auto parts = transact(commands, resend);
    sent = stats().ours();
    return parts;
  }

  // Waits until no packet of ours with writes can still reach the card (a no-op unless
  // one went unanswered), so that what is read next is the truth. See fenced_transport.hpp;
  // transports without a ledger have nothing to wait for.
  virtual FenceReport fence() { return {}; }

  // "192.168.1.121" (":PORT" appended when not 27181), for messages.
  virtual std::string describe() const = 0;

  virtual TransportStats stats() const = 0;
};

// One transport to a card for several users on several threads (the PassthroughPorts of
// a card's SSERIAL ports in a fleet): one packet on the wire at a time, and one packet
// count, so that each user's check for another host counts the others' packets as ours.
class SharedTransport final : public Lbp16Transport {
 public:
  explicit SharedTransport(std::unique_ptr<Lbp16Transport> inner) : inner_(std::move(inner)) {}
  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands,
                                   Resend resend = Resend::IfReadOnly) override {
    std::lock_guard lock(mutex_);
    return inner_->transact(commands, resend);
  }
  std::vector<lbp::Bytes> transact_counted(std::span<const lbp::lbp16::Command> commands, Resend resend,
                                           std::uint64_t& sent) override {
    std::lock_guard lock(mutex_);
    auto parts = inner_->transact(commands, resend);
    sent = inner_->stats().ours();
    return parts;
  }
  FenceReport fence() override {
    std::lock_guard lock(mutex_);
    return inner_->fence();
  }
  std::string describe() const override { return inner_->describe(); }
  TransportStats stats() const override {
    std::lock_guard lock(mutex_);
    return inner_->stats();
  }

 private:
  std::unique_ptr<Lbp16Transport> inner_;
  mutable std::mutex mutex_;
};

}  // namespace i20::eth
