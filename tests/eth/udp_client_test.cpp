// SPDX-License-Identifier: GPL-2.0-or-later
// UdpClient against scripted cards and the virtual card on loopback: replies only from
// the card's own address, never of the wrong size, resends only what may be resent.
#include "eth/udp_client.hpp"

#include <gtest/gtest.h>

#include "error/error.hpp"
#include "eth/errors.hpp"
#include "fixtures.hpp"
#include "programs_timing.hpp"

using namespace i20;
using namespace i20::eth;
using namespace std::chrono_literals;
namespace lbp16 = i20::lbp::lbp16;
using test::ScriptedBoard;

namespace {

// For cards that never answer: the timeout is the point, so keep it short.
UdpOptions quick(unsigned retries = 2) {
  return UdpOptions{.timeout = 30ms, .max_timeout = 1000ms, .retries = retries};
}

// For cards that do answer: a loaded or instrumented host may take long to schedule the
// scripted card's thread; a reply is awaited as long as it takes (the ceiling).
UdpOptions patient(unsigned retries = 2) {
  return UdpOptions{.timeout = 1000ms, .max_timeout = 5000ms, .retries = retries};
}

// Waits until the scripted card has logged `n` requests (its thread logs them after the
// client sent them), then says whether it logged exactly that many.
bool logged_requests(const ScriptedBoard& card, std::size_t n) {
  test::eventually([&] { return card.requests() >= n; });
  return card.requests() == n;
}

const lbp16::Command kCookie = lbp16::read_hm2(0x0100);

}  // namespace

TEST(EthUdpClient, ReadsTheCookieFromTheVirtualCard) {
  test::RunningBoard card;
  // One request, one reply: the wait is long enough that a host starved for a while (a
  // sanitizer build under load) does not make the client resend, which is not this test's subject.
  auto options = programs_timing::udp();
  options.timeout = std::chrono::milliseconds(5000);
  options.max_timeout = std::chrono::milliseconds(5000);
  UdpClient client(card.address().ip, card.address().port, options);
  const auto reply = client.transact(std::span(&kCookie, 1));
  ASSERT_EQ(reply.size(), 1u);
  EXPECT_EQ(reply[0], lbp::from_hex("fecaaa55"));  // the manual's ELBPCOM sample
  EXPECT_EQ(client.stats().packets_sent, 1u);
  EXPECT_EQ(client.stats().replies, 1u);
}

TEST(EthUdpClient, RepliesFromAnotherSenderAreIgnored) {
  ScriptedBoard card([](const lbp::Bytes& request, const auto& client, ScriptedBoard::Sockets s) {
    const lbp::Bytes good = test::zero_card_reply(request);
    lbp::Bytes forged = good;
    forged.back() = 0xEE;
    s.impostor.send_to(boost::asio::buffer(forged), client);  // same size, wrong address:port
    // Kept: a head start for the forged datagram. Loopback delivers in send order already;
    // no event says the client's socket holds it (its statistics are the client thread's),
    // and a late forgery would fail the test loudly (foreign_ignored 0), not pass it wrongly.
    std::this_thread::sleep_for(2ms);
    s.card.send_to(boost::asio::buffer(good), client);
  });
  UdpClient client("127.0.0.1", card.port(), patient());
  const auto reply = client.transact(std::span(&kCookie, 1));
  EXPECT_EQ(reply[0], lbp::Bytes(4, 0));  // the card's zeros, not the impostor's 0xEE
  EXPECT_EQ(client.stats().foreign_ignored, 1u);
  EXPECT_EQ(client.stats().packets_sent, 1u);
}

TEST(EthUdpClient, OnlyForeignRepliesMeanTimeout) {
  ScriptedBoard card([](const lbp::Bytes& request, const auto& client, ScriptedBoard::Sockets s) {
    s.impostor.send_to(boost::asio::buffer(test::zero_card_reply(request)), client);
  });
  UdpClient client("127.0.0.1", card.port(), quick(0));
  EXPECT_THROW(client.transact(std::span(&kCookie, 1)), link::TimeoutError);
  EXPECT_EQ(client.stats().foreign_ignored, 1u);
}

TEST(EthUdpClient, ReplyOfTheWrongSizeIsAnError) {
  for (int delta : {-1, +2}) {
    ScriptedBoard card([delta](const lbp::Bytes& request, const auto& client, ScriptedBoard::Sockets s) {
      lbp::Bytes reply = test::zero_card_reply(request);
      reply.resize(static_cast<std::size_t>(static_cast<int>(reply.size()) + delta));
      s.card.send_to(boost::asio::buffer(reply), client);
    });
    UdpClient client("127.0.0.1", card.port(), patient());
    try {
      client.transact(std::span(&kCookie, 1));
      FAIL() << "accepted a reply " << delta << " bytes off";
    } catch (const BadReplyError& e) {
      EXPECT_NE(std::string(e.what()).find("were expected"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(logged_requests(card, 1)) << "a bad reply is reported, not retried";
  }
}

TEST(EthUdpClient, StaleRepliesAreDroppedBySequenceNumber) {
  // The card answers every request twice: once with a stale tag (as a late reply to an
  // earlier packet would), then properly.
  ScriptedBoard card([](const lbp::Bytes& request, const auto& client, ScriptedBoard::Sockets s) {
    lbp::Bytes stale = test::zero_card_reply(request);
    stale[0] ^= 0x55;
    stale.resize(stale.size() + 4);  // a different size too: still not an error, it is not ours
    s.card.send_to(boost::asio::buffer(stale), client);
    s.card.send_to(boost::asio::buffer(test::zero_card_reply(request)), client);
  });
  UdpClient client("127.0.0.1", card.port(), patient());
  EXPECT_NO_THROW(client.transact(std::span(&kCookie, 1)));
  EXPECT_EQ(client.stats().stale_ignored, 1u);
}

TEST(EthUdpClient, SilentCardTimesOutAfterBoundedResendsOfReads) {
  ScriptedBoard card([](const lbp::Bytes&, const auto&, ScriptedBoard::Sockets) {});
  UdpClient client("127.0.0.1", card.port(), quick(2));
  const auto t0 = std::chrono::steady_clock::now();
  try {
    client.transact(std::span(&kCookie, 1));
    FAIL();
  } catch (const link::TimeoutError& e) {
    EXPECT_NE(std::string(e.what()).find("3 attempts"), std::string::npos) << e.what();
  }
  EXPECT_GE(std::chrono::steady_clock::now() - t0, 30ms + 60ms + 120ms) << "each resend waits twice as long";
  EXPECT_TRUE(logged_requests(card, 3));
  EXPECT_EQ(client.stats().resends, 2u);
  EXPECT_EQ(client.stats().timeouts, 3u);
}

TEST(EthUdpClient, PacketsWithWritesAreNotResentUnlessIdempotent) {
  ScriptedBoard card([](const lbp::Bytes&, const auto&, ScriptedBoard::Sockets) {});
  UdpClient client("127.0.0.1", card.port(), quick(2));
  const lbp16::Command write = lbp16::write_hm2(0x1000, 0x1234u);
  try {
    client.transact(std::span(&write, 1));
    FAIL();
  } catch (const link::TimeoutError& e) {
    EXPECT_NE(std::string(e.what()).find("may or may not have taken effect"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(logged_requests(card, 1));
  EXPECT_THROW(client.transact(std::span(&write, 1), Resend::Idempotent), link::TimeoutError);
  EXPECT_TRUE(logged_requests(card, 4));
  EXPECT_THROW(client.transact(std::span(&kCookie, 1), Resend::Never), link::TimeoutError);
  EXPECT_TRUE(logged_requests(card, 5));
}

TEST(EthUdpClient, LostReplyIsRecoveredByResendingAReadOnlyPacket) {
  std::atomic<int> seen{0};
  ScriptedBoard card([&](const lbp::Bytes& request, const auto& client, ScriptedBoard::Sockets s) {
    if (seen++ == 0) return;  // the first reply is lost
    s.card.send_to(boost::asio::buffer(test::zero_card_reply(request)), client);
  });
  UdpClient client("127.0.0.1", card.port(),
                   UdpOptions{.timeout = 30ms, .max_timeout = 5000ms, .retries = 2});
  EXPECT_NO_THROW(client.transact(std::span(&kCookie, 1)));
  EXPECT_GE(client.stats().resends, 1u);
  EXPECT_LE(client.stats().resends, 2u);
}

TEST(EthUdpClient, WriteOnlyPacketStillGetsAReplyThroughTheSequenceTag) {
  test::RunningBoard card;
  UdpClient client(card.address().ip, card.address().port, patient());
  const lbp16::Command write = lbp16::write_hm2(0x7000, 0xCAFEF00Du);
  const auto reply = client.transact(std::span(&write, 1));
  ASSERT_EQ(reply.size(), 1u);
  EXPECT_TRUE(reply[0].empty());
  EXPECT_EQ(client.stats().replies, 1u);
  const lbp16::Command read = lbp16::read_hm2(0x7000);
  EXPECT_EQ(lbp::read_le(client.transact(std::span(&read, 1))[0]), 0xCAFEF00Du);
}

TEST(EthUdpClient, RejectsBadAddresses) {
  EXPECT_THROW(UdpClient("card.local", lbp::lbp16::kUdpPort, programs_timing::udp()), UsageError);
  EXPECT_THROW(UdpClient("192.168.1", lbp::lbp16::kUdpPort, programs_timing::udp()), UsageError);
}

TEST(EthUdpClient, ASlowCardsRoundTripIsLearntAndItsWritesAreAnsweredInTime) {
  // Every reply leaves 40 ms after its request arrived (a loaded host), past the 10 ms floor.
  ScriptedBoard card([](const lbp::Bytes& request, const auto& client, ScriptedBoard::Sockets s) {
    std::this_thread::sleep_for(40ms);  // the subject: a late reply, not an ordering
    s.card.send_to(boost::asio::buffer(test::zero_card_reply(request)), client);
  });
  UdpClient client("127.0.0.1", card.port(),
                   UdpOptions{.timeout = 10ms, .max_timeout = 5000ms, .retries = 2});
  EXPECT_NO_THROW(client.transact(std::span(&kCookie, 1)));  // the first may need resends
  ASSERT_TRUE(client.reply_timeout().smoothed());
  EXPECT_GE(*client.reply_timeout().smoothed(), 40ms) << "measured from the send of the attempt it answers";
  const auto resends = client.stats().resends;
  const lbp16::Command write = lbp16::write_hm2(0x1000, 0x1234u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_NO_THROW(client.transact(std::span(&write, 1))) << "a write is sent once and must be waited for";
    EXPECT_NO_THROW(client.transact(std::span(&kCookie, 1)));
  }
  EXPECT_EQ(client.stats().resends, resends) << "a learnt round trip needs no resends";
  EXPECT_EQ(card.requests(), client.stats().packets_sent);
}

// The estimator alone: no sockets, no clock.
TEST(EthReplyTimeout, StartsAtTheFloorAndStaysThereForAFastCard) {
  ReplyTimeout t(50ms, 1000ms);
  EXPECT_EQ(t.current(), 50ms);
  EXPECT_FALSE(t.smoothed());
  for (int i = 0; i < 20; ++i) t.measured(300us);  // loopback or a LAN
  EXPECT_EQ(t.current(), 50ms) << "a fast card keeps the floor";
  EXPECT_EQ(*t.smoothed(), 300us);
}

TEST(EthReplyTimeout, ASlowHostRaisesItAboveItsRoundTrips) {
  ReplyTimeout t(50ms, 1000ms);
  t.measured(80ms);  // RFC 6298: smoothed 80, deviation 40, so 80 + 4 x 40
  EXPECT_EQ(t.current(), 240ms);
  for (int i = 0; i < 50; ++i) t.measured(80ms);
  EXPECT_GT(t.current(), 80ms) << "always above the round trips it has seen";
  EXPECT_LT(t.current(), 100ms) << "and close to them once they are steady";
}

TEST(EthReplyTimeout, JitterWidensItBeyondTheLongestRoundTrip) {
  ReplyTimeout t(20ms, 1000ms);
  for (int i = 0; i < 50; ++i) t.measured(i % 2 ? 60ms : 10ms);
  EXPECT_GT(t.current(), 60ms);
}

TEST(EthReplyTimeout, TimeoutsDoubleItUpToTheCeilingAndAMeasurementEndsTheBackOff) {
  ReplyTimeout t(30ms, 100ms);
  t.timed_out();
  EXPECT_EQ(t.current(), 60ms);
  t.timed_out();
  EXPECT_EQ(t.current(), 100ms) << "the ceiling";
  t.timed_out();
  EXPECT_EQ(t.current(), 100ms);
  t.measured(1ms);
  EXPECT_EQ(t.current(), 30ms);
}

TEST(EthReplyTimeout, CeilingBoundsAnyRoundTrip) {
  ReplyTimeout t(50ms, 1000ms);
  t.measured(5000ms);
  EXPECT_EQ(t.current(), 1000ms);
}

TEST(EthReplyTimeout, PatienceOfOneSendingIsThatOfEveryBackedOffAttempt) {
  ReplyTimeout t(30ms, 1000ms);
  EXPECT_EQ(t.patience(1), 30ms);
  EXPECT_EQ(t.patience(3), 30ms + 60ms + 120ms);
  ReplyTimeout capped(30ms, 100ms);
  EXPECT_EQ(capped.patience(3), 30ms + 60ms + 100ms);
}

TEST(EthReplyTimeout, AFloorAboveTheCeilingIsTheCeiling) {
  ReplyTimeout t(200ms, 100ms);
  EXPECT_EQ(t.current(), 200ms) << "the floor wins: the caller asked for at least that";
}
