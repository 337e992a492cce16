// SPDX-License-Identifier: GPL-2.0-or-later
// Late requests. UDP may deliver a request long after the client gave up on it (a
// congested switch, a busy host): the card then executes it late, between the client's
// later packets, on state they share (SSLBP's CS, INTERFACE and COMMAND registers, an
// 8I20's NV access mode). Sequence tags (udp_client.hpp) keep a late *reply* from being
// taken for the current one; they cannot stop a late *request* from running.
//
// FencedTransport sits between the LBP16 users and the UDP client and keeps a ledger of
// arrivals by the card's own count of the packets it received (space 6 RXUDPCount, 7I96S
// and 7I92T manuals, "SPACE 6 LBP STATUS/CONTROL AREA"), read first in every packet:
//
// - Detection: between two of our replies the count moves by one (the new packet) plus
//   whatever else the card received in between. Anything beyond the earlier attempts of the
//   same packet is a late packet of ours or a foreign host's.
// - Fence: after a packet with writes went unanswered (or needed a resend), nothing else is
//   sent until the card's count shows that every packet of ours reached it, or until
//   FenceOptions::bound has passed; only read-only probes of the count go out meanwhile.
//   After the fence the card cannot receive that packet any more (within the bound), so
//   whatever the caller reads next is the truth. A packet that had not arrived by then is
//   taken as lost: if it arrives after all, the count shows it and the next exchange fails
//   with LatePacketError instead of succeeding on disturbed state.
// - A late writer that ran between two of our packets (possible only past the bound)
//   fails that exchange with LatePacketError: its results are discarded.
//
// Foreign packets are counted, not refused: the users who care (the running-host check,
// PassthroughPort's check for another host) read the count too and decide.
#pragma once

#include <chrono>
#include <deque>
#include <memory>

#include "eth/transport.hpp"

namespace i20::eth {

struct FenceOptions {
  // How long after its last send a packet may still reach the card. A LAN delivers in well
  // under a millisecond, a congested switch or a busy host holds a datagram back for a few
  // hundred (issue 18 measured up to 400 ms); a second covers that with room. Only paid when
  // a packet with writes went unanswered and never arrived (a lost, not a late, request).
  link::Given<std::chrono::milliseconds> bound;
  // Pause between read-only probes while fencing; doubles up to `max_probe_pause`.
  link::Given<std::chrono::milliseconds> probe_pause;
  link::Given<std::chrono::milliseconds> max_probe_pause;
};

class FencedTransport final : public Lbp16Transport {
 public:
  explicit FencedTransport(std::unique_ptr<Lbp16Transport> inner, FenceOptions options);

  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands,
                                   Resend resend = Resend::IfReadOnly) override;
  std::vector<lbp::Bytes> transact_counted(std::span<const lbp::lbp16::Command> commands, Resend resend,
                                           std::uint64_t& sent) override;
  FenceReport fence() override;
  std::string describe() const override { return inner_->describe(); }
  TransportStats stats() const override;

 private:
  std::vector<lbp::Bytes> exchange(std::span<const lbp::lbp16::Command> commands, Resend resend);
  void account(std::uint16_t received, std::uint64_t sends, bool writes);

  std::unique_ptr<Lbp16Transport> inner_;
  FenceOptions options_;
  bool based_ = false;
  std::uint16_t base_ = 0;                   // RXUDPCount minus our packets, when all ours had arrived
  std::uint16_t last_received_ = 0;          // RXUDPCount at our latest reply
  std::uint16_t last_sent_ = 0;              // our packets by then (low 16 bits)
  std::uint16_t missing_ = 0;                // our packets the card had not received by then
  std::uint64_t writers_at_risk_ = 0;        // our packets with writes that may still arrive
  std::uint64_t presumed_lost_writers_ = 0;  // given up on at a fence: if they arrive, it is late
  bool unsettled_ = false;  // packets sent before the ledger began may still arrive: fence first
  TransportStats late_;     // late_arrivals, fences, fence_waits
  // Our sends within the last `bound` (when, how many): only these may still arrive, so
  // TransportStats::unarrived is at most their number (older ones not arrived are lost).
  std::deque<std::pair<std::chrono::steady_clock::time_point, std::uint64_t>> recent_sends_;
  void record_sends(std::uint64_t sends);
};

}  // namespace i20::eth
