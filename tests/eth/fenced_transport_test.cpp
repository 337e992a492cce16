// SPDX-License-Identifier: GPL-2.0-or-later
// FencedTransport's ledger of arrivals (issue 18 item 1), against a card model whose
// network holds chosen requests back: a late request must reach the card before anything
// that follows a timeout does, and a request given up on that turns up later must fail
// the exchange it lands in.
#include "eth/fenced_transport.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <deque>
#include <map>
#include <optional>
#include <thread>

#include "eth/errors.hpp"
#include "eth/running_host.hpp"
#include "lbp/bytes.hpp"
#include "programs_timing.hpp"

using namespace i20;
namespace lbp16 = lbp::lbp16;

namespace {

// A card that counts the packets it receives (RXUDPCount) behind a network the test steers:
// a request can be held back for a number of later sends, or dropped; a reply can be lost.
// It records the order in which the card executed packets, by the value each one wrote to
// space 6 address 0x1A (a marker only these tests use).
class HeldBackBoard final : public eth::Lbp16Transport {
 public:
  // Resent: the first attempt is held back, the client resends (a second send, as
  // UdpClient does for a read-only packet) and that attempt is answered.
  enum class Fate { Deliver, LoseReply, HoldBack, Drop, Resent };

  void plan(std::uint64_t send, Fate fate, unsigned held_for = 0) { plans_[send] = {fate, held_for}; }
  // Holds back the first packet that writes `marker`, whichever send it is.
  void hold_marker(std::uint16_t marker, unsigned held_for) { held_marker_ = {marker, held_for}; }
  void foreign(unsigned packets) { received_ += static_cast<std::uint16_t>(packets); }

  std::vector<lbp::Bytes> transact(std::span<const lbp16::Command> commands, eth::Resend) override {
    const std::uint64_t send = ++stats_.packets_sent;
    release_due();
    auto [fate, held_for] = plans_.count(send) ? plans_[send] : Plan{};
    if (held_marker_ && writes_marker(commands, held_marker_->first)) {
      fate = Fate::HoldBack;
      held_for = held_marker_->second;
      held_marker_.reset();
    }
    if (fate == Fate::Drop) throw link::TimeoutError("dropped");
    if (fate == Fate::Resent) {
      held_.push_back({send + held_for, {commands.begin(), commands.end()}});
      ++stats_.packets_sent;
      return execute(commands);
    }
    if (fate == Fate::HoldBack) {
      held_.push_back({send + held_for, {commands.begin(), commands.end()}});
      throw link::TimeoutError("held back");
    }
    auto parts = execute(commands);
    if (fate == Fate::LoseReply) throw link::TimeoutError("reply lost");
    return parts;
  }
  std::string describe() const override { return "held-back card"; }
  eth::TransportStats stats() const override { return stats_; }

  std::vector<std::uint16_t> executed_markers() const { return markers_; }
  std::size_t held() const { return held_.size(); }

 private:
  struct Plan {
    Fate fate = Fate::Deliver;
    unsigned held_for = 0;
  };
  struct Held {
    std::uint64_t due = 0;  // delivered just before this send
    std::vector<lbp16::Command> commands;
  };

  void release_due() {
    while (!held_.empty() && held_.front().due <= stats_.packets_sent) {
      execute(held_.front().commands);
      held_.pop_front();
    }
  }
  std::vector<lbp::Bytes> execute(std::span<const lbp16::Command> commands) {
    ++received_;
    std::vector<lbp::Bytes> parts;
    for (const auto& c : commands) {
      if (c.word.write && c.word.space == lbp16::space::kStatus && c.address == kMarker)
        markers_.push_back(static_cast<std::uint16_t>(lbp::read_le(c.data)));
      if (c.word.write) {
        parts.emplace_back();
        continue;
      }
      const bool count = c.word.space == lbp16::space::kStatus && c.address == eth::kRxUdpCountAddress;
      parts.push_back(lbp::to_le(count ? received_ : 0, c.reply_bytes()));
    }
    return parts;
  }

  static bool writes_marker(std::span<const lbp16::Command> commands, std::uint16_t value) {
    return std::any_of(commands.begin(), commands.end(), [&](const lbp16::Command& c) {
      return c.word.write && c.word.space == lbp16::space::kStatus && c.address == kMarker &&
             lbp::read_le(c.data) == value;
    });
  }

  static constexpr std::uint16_t kMarker = 0x1A;
  std::optional<std::pair<std::uint16_t, unsigned>> held_marker_;
  std::map<std::uint64_t, Plan> plans_;
  std::deque<Held> held_;
  std::uint16_t received_ = 100;  // another client's packets came before ours
  std::vector<std::uint16_t> markers_;
  eth::TransportStats stats_;
};

lbp16::Command mark(std::uint16_t value) {
  return lbp16::write(lbp16::space::kStatus, 0x1A, lbp16::Width::Bits16, lbp::to_le(value, 2));
}
lbp16::Command some_read() {
  return lbp16::read(lbp16::space::kStatus, 0x18, lbp16::Width::Bits16);
}

struct Fixture {
  HeldBackBoard* card = nullptr;
  std::unique_ptr<eth::FencedTransport> bus;
  explicit Fixture(eth::FenceOptions options = programs_timing::fence()) {
    auto inner = std::make_unique<HeldBackBoard>();
    card = inner.get();
    options.probe_pause = std::chrono::milliseconds(0);
    bus = std::make_unique<eth::FencedTransport>(std::move(inner), options);
  }
  void write(std::uint16_t value) {
    const auto c = mark(value);
    bus->transact(std::span(&c, 1), eth::Resend::Never);
  }
  void read() {
    const auto c = some_read();
    bus->transact(std::span(&c, 1));
  }
};

TEST(FencedTransport, ALateWriteLandsBeforeAnythingThatFollowsItsTimeout) {
  Fixture f;
  f.write(1);
  f.card->plan(2, HeldBackBoard::Fate::HoldBack, 4);  // arrives while the 4th probe after it goes out
  EXPECT_THROW(f.write(2), link::TimeoutError);
  f.write(3);  // the fence runs first
  EXPECT_EQ(f.card->executed_markers(), (std::vector<std::uint16_t>{1, 2, 3}))
      << "the late write ran after a later one";
  EXPECT_EQ(f.bus->stats().fences, 1u);
  EXPECT_EQ(f.bus->stats().lost_writers, 0u);
}

TEST(FencedTransport, AFenceReportsWhetherTheUnansweredPacketArrived) {
  Fixture f;
  f.write(1);
  f.card->plan(2, HeldBackBoard::Fate::LoseReply);  // it ran; only the reply is gone
  EXPECT_THROW(f.write(2), link::TimeoutError);
  const eth::FenceReport r = f.bus->fence();
  EXPECT_TRUE(r.needed);
  EXPECT_TRUE(r.all_arrived);
  EXPECT_EQ(f.bus->fence().needed, false) << "nothing is at risk any more";
}

// Our packets not yet counted by the card (the running-host watch counts them as ours if
// they arrive): a held-back one while it may still come, and never one sent longer ago than
// the bound, when a lost one is taken as lost.
TEST(FencedTransport, UnarrivedCountsOnlyOurRecentPacketsTheCardHasNotCounted) {
  eth::FenceOptions short_bound = programs_timing::fence();
  short_bound.bound = std::chrono::milliseconds(50);
  Fixture f(short_bound);
  f.read();
  EXPECT_EQ(f.bus->stats().unarrived, 0u);
  f.card->plan(2, HeldBackBoard::Fate::Drop);  // lost on the way: never counted
  EXPECT_THROW(f.read(), link::TimeoutError);
  f.read();
  EXPECT_EQ(f.bus->stats().unarrived, 1u) << "the lost read may be a late one, within the bound";
  std::this_thread::sleep_for(std::chrono::milliseconds(60));  // the subject: the bound's passing
  EXPECT_EQ(f.bus->stats().unarrived, 0u) << "older than the bound: lost, not still to come";
}

TEST(FencedTransport, ReadsNeedNoFence) {
  Fixture f;
  f.read();
  f.card->plan(2, HeldBackBoard::Fate::HoldBack, 3);
  EXPECT_THROW(f.read(), link::TimeoutError);
  EXPECT_FALSE(f.bus->fence().needed);
  f.read();
  f.read();
  EXPECT_NO_THROW(f.read()) << "a late read changes nothing and fails nothing";
  EXPECT_EQ(f.bus->stats().late_arrivals, 1u);
  EXPECT_EQ(f.bus->stats().foreign_arrivals, 0u);
}

TEST(FencedTransport, AWriteGivenUpOnThatArrivesAfterAllFailsTheExchangeItLandsIn) {
  eth::FenceOptions no_wait = programs_timing::fence();
  no_wait.bound = std::chrono::milliseconds(0);
  Fixture f(no_wait);
  f.write(1);
  f.card->plan(2, HeldBackBoard::Fate::HoldBack, 1000);  // far past the bound
  EXPECT_THROW(f.write(2), link::TimeoutError);
  const eth::FenceReport r = f.bus->fence();
  EXPECT_TRUE(r.needed);
  EXPECT_FALSE(r.all_arrived);
  EXPECT_EQ(r.missing, 1u);
  EXPECT_EQ(f.bus->stats().lost_writers, 1u);
  f.read();
  // Now the network delivers it, between two of our packets.
  f.card->foreign(1);  // the late arrival, in the card's count
  EXPECT_THROW(f.read(), eth::LatePacketError);
}

// The issue 18 trial that still printed a false "the card reset itself": the very first
// packet (read-only) was resent, its first attempt arrived late, just while a fence waited
// for a lost DOIT packet, and the ledger, which had taken every attempt before its first
// answer as arrived, took that arrival for the DOIT's. The poll that followed read an
// older command's result as STATUS.
TEST(FencedTransport, AnEarlierAttemptOfTheFirstPacketIsNotTakenForALaterPacket) {
  Fixture f;
  f.card->plan(1, HeldBackBoard::Fate::Resent, 3);  // sends 1 and 2; the first arrives 3 sends later
  f.read();
  f.card->hold_marker(2, 6);
  EXPECT_THROW(f.write(2), link::TimeoutError);
  f.write(3);  // the fence first: it must wait for write 2 itself
  for (int i = 0; i < 8; ++i) f.read();
  EXPECT_EQ(f.card->executed_markers(), (std::vector<std::uint16_t>{2, 3}))
      << "the late write ran after a later one: the fence took another arrival for it";
  EXPECT_EQ(f.card->held(), 0u);
}

TEST(FencedTransport, AnUnansweredFirstPacketIsNotTakenAsArrived) {
  Fixture f;
  f.card->plan(1, HeldBackBoard::Fate::HoldBack, 4);  // the very first packet, with writes
  EXPECT_THROW(f.write(1), link::TimeoutError);
  const eth::FenceReport r = f.bus->fence();
  EXPECT_TRUE(r.needed);
  EXPECT_TRUE(r.all_arrived) << "the fence waited until the count showed it";
  EXPECT_EQ(f.card->executed_markers(), (std::vector<std::uint16_t>{1}));
  EXPECT_EQ(f.card->held(), 0u);
}

TEST(FencedTransport, ForeignPacketsAreCountedNotRefused) {
  Fixture f;
  f.read();
  f.card->foreign(3);
  EXPECT_NO_THROW(f.read());
  EXPECT_EQ(f.bus->stats().foreign_arrivals, 3u);
  EXPECT_EQ(f.bus->stats().late_arrivals, 0u);
}

}  // namespace
