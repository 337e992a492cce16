// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/fenced_transport.hpp"

#include <algorithm>
#include <thread>

#include "eth/errors.hpp"
#include "eth/running_host.hpp"
#include "lbp/bytes.hpp"
#include "link/wait_bound.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
using Clock = std::chrono::steady_clock;

namespace {

// Writes that change the card. WaituS (space 4) only delays the packet it is in.
bool changes_state(std::span<const lbp16::Command> commands) {
  return std::any_of(commands.begin(), commands.end(), [](const lbp16::Command& c) {
    return c.word.write && !(c.word.space == lbp16::space::kTimers && c.address == kWaitMicrosecondsAddress);
  });
}

}  // namespace

FencedTransport::FencedTransport(std::unique_ptr<Lbp16Transport> inner, FenceOptions options)
    : inner_(std::move(inner)), options_(options) {}

TransportStats FencedTransport::stats() const {
  TransportStats s = inner_->stats();
  s.late_arrivals = late_.late_arrivals;
  s.foreign_arrivals = late_.foreign_arrivals;
  s.fences = late_.fences;
  s.lost_writers = late_.lost_writers;
  // Packets of ours not counted yet that may still come: no more than we sent within the
  // bound (a lossy session's lost reads would otherwise pile up and hide another host).
  const auto since = Clock::now() - options_.bound.get();
  std::uint64_t recent = 0;
  for (const auto& [at, sends] : recent_sends_)
    if (at >= since) recent += sends;
  s.unarrived = std::min<std::uint64_t>(missing_, recent);
  return s;
}

std::vector<lbp::Bytes> FencedTransport::transact(std::span<const lbp16::Command> commands, Resend resend) {
  // A packet that will not be sent needs no fence before it.
  link::WaitBound::require_time_left(describe());
  if (writers_at_risk_ > 0 || unsettled_) fence();
  return exchange(commands, resend);
}

std::vector<lbp::Bytes> FencedTransport::transact_counted(std::span<const lbp16::Command> commands,
                                                          Resend resend, std::uint64_t& sent) {
  auto parts = transact(commands, resend);
  sent = inner_->stats().ours();
  return parts;
}

std::vector<lbp::Bytes> FencedTransport::exchange(std::span<const lbp16::Command> commands, Resend resend) {
  std::vector<lbp16::Command> packet{received_count_read()};
  packet.insert(packet.end(), commands.begin(), commands.end());
  const bool writes = changes_state(commands);
  const std::uint64_t before = inner_->stats().packets_sent;
  std::vector<lbp::Bytes> parts;
  try {
    parts = inner_->transact(packet, resend);
  } catch (const link::LinkError&) {
    // Unanswered (or answered wrongly): every attempt may still reach the card.
    if (writes) writers_at_risk_ += inner_->stats().packets_sent - before;
    record_sends(inner_->stats().packets_sent - before);
    throw;
  }
  const std::uint64_t sends = inner_->stats().packets_sent - before;
  record_sends(sends);
  account(static_cast<std::uint16_t>(lbp::read_le(parts.front())), sends, writes);
  parts.erase(parts.begin());
  return parts;
}

void FencedTransport::record_sends(std::uint64_t sends) {
  const auto now = Clock::now();
  while (!recent_sends_.empty() && recent_sends_.front().first < now - options_.bound.get())
    recent_sends_.pop_front();
  if (sends > 0) recent_sends_.emplace_back(now, sends);
}

// Updates the ledger with the count read at the start of our latest answered packet.
// `missing`: our packets the card had not received by then.
void FencedTransport::account(std::uint16_t received, std::uint64_t sends, bool writes) {
  const auto sent = static_cast<std::uint16_t>(inner_->stats().ours());
  if (!based_) {
    based_ = true;
    // Of our packets so far only the attempt that answered is known to have arrived. The
    // others (this packet's resends, packets that went unanswered before it) may have
    // arrived before this count or may still come: taken as still to come, so that a late
    // one is never mistaken for a later packet of ours that a fence waits for. The next
    // packet first waits until they are in, or for the bound (then they are lost).
    const auto earlier = static_cast<std::uint16_t>(sent - 1);
    base_ = static_cast<std::uint16_t>(received - 1);
    missing_ = earlier;
    unsettled_ = earlier > 0;
    last_received_ = received;
    last_sent_ = sent;
    return;
  }
  const auto arrived_since = static_cast<std::uint16_t>(received - last_received_);
  const auto sent_since = static_cast<std::uint16_t>(sent - static_cast<std::uint16_t>(last_sent_));
  auto missing = static_cast<std::int16_t>(static_cast<std::uint16_t>(base_ + sent - received));
  last_received_ = received;
  last_sent_ = sent;
  // Arrivals beyond everything we sent since our previous reply: packets sent before it
  // (late ones of ours), or another host's.
  const std::uint16_t from_before = arrived_since > sent_since ? arrived_since - sent_since : 0;
  std::uint16_t foreign = 0;
  if (missing < 0) {
    foreign = static_cast<std::uint16_t>(-missing);
    base_ = static_cast<std::uint16_t>(base_ + foreign);
    missing = 0;
    late_.foreign_arrivals += foreign;
  }
  const std::uint16_t late = from_before > foreign ? from_before - foreign : 0;
  late_.late_arrivals += late;
  missing_ = static_cast<std::uint16_t>(missing);
  if (missing_ == 0) {
    writers_at_risk_ = 0;  // everything of ours is in: nothing can come late
    unsettled_ = false;
  } else if (writes) {
    writers_at_risk_ += sends - 1;  // earlier attempts of this packet may still come
  }
  if (foreign > 0 && presumed_lost_writers_ > 0) {
    // A packet given up on at a fence may be what just arrived: it ran between our last
    // two packets, on what they share.
    presumed_lost_writers_ -= std::min<std::uint64_t>(presumed_lost_writers_, foreign);
    throw LatePacketError(
        "a packet to " + describe() +
        " given up on as lost reached the card after all, between two later packets "
        "(or another host sent " +
        std::to_string(foreign) +
        "); the results of this exchange were discarded: read back what the command touched");
  }
}

FenceReport FencedTransport::fence() {
  FenceReport report;
  if (writers_at_risk_ == 0 && !unsettled_) return report;
  report.needed = true;
  ++late_.fences;
  // The fence runs its own bounded course whatever is left of the operation: cut short, a
  // lost packet with writes could still reach the card after the command ended.
  const link::WaitBound unbounded{std::nullopt};
  const auto start = Clock::now();
  auto pause = options_.probe_pause;
  for (;;) {
    try {
      // Read-only probes of the count: the ledger moves with each answer.
      exchange(std::span<const lbp16::Command>(), Resend::IfReadOnly);
    } catch (const link::TimeoutError&) {
      // A lost probe costs nothing but time.
    }
    if (missing_ == 0) break;
    if (Clock::now() - start >= options_.bound) {
      // Not arrived within the bound: taken as lost. Should one still arrive, the count
      // exceeds ours and the exchange it lands in fails (account()).
      report.all_arrived = false;
      report.missing = missing_;
      late_.lost_writers += writers_at_risk_;
      presumed_lost_writers_ += writers_at_risk_;
      base_ = static_cast<std::uint16_t>(base_ - missing_);
      missing_ = 0;
      break;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, options_.max_probe_pause.get());
  }
  writers_at_risk_ = 0;
  unsettled_ = false;
  report.waited = std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start);
  return report;
}

}  // namespace i20::eth
