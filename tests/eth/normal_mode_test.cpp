// SPDX-License-Identifier: GPL-2.0-or-later
// NormalModeSession: live BUSV/TEMPERATURE/FAULT/STATUS over SSLBP normal mode.
#include "eth/normal_mode.hpp"

#include <gtest/gtest.h>

#include "eth/errors.hpp"
#include "fixtures.hpp"
#include "programs_timing.hpp"

using namespace i20;
using namespace i20::eth;
using namespace std::chrono_literals;

TEST(EthNormalMode, StartsReadsUnitNumberAndStreamsTheAmplifiersValues) {
  test::RunningBoard card;
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) {
    amp.world().settings().bus_volts = 320.0;
    amp.world().settings().temperature_c = 35.0;
  });
  const auto session = NormalModeSession::open(card.target(0), programs_timing::normal_mode());
  EXPECT_EQ(session->unit_number(0), 0x00012345u);
  EXPECT_THROW(session->unit_number(1), UsageError);

  const LiveStatus s = session->wait_for_sample(500ms);
  const ChannelSample* ch = s.channel(0);
  ASSERT_NE(ch, nullptr);
  EXPECT_EQ(ch->bus_voltage, 32000);  // 10 mV units: the manual's RPD example value
  EXPECT_DOUBLE_EQ(ch->bus_volts(), 320.0);
  // "LSW = Card Temperature in oC" (8I20 manual, 8I20 SPECIFIC INTERFACE REGISTER 0
  // DEFINITIONS): whole degrees on the wire, the same degrees to the caller.
  EXPECT_EQ(ch->temperature, 35);
  EXPECT_DOUBLE_EQ(ch->temperature_celsius(), 35.0);
  EXPECT_FALSE(ch->transfer_failed);
  EXPECT_EQ(ch->fault, 0);

  // The world changes, the next samples follow.
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { amp.world().settings().bus_volts = 300.0; });
  std::uint16_t seen = 0;
  for (int i = 0; i < 20 && seen != 30000; ++i)
    seen = session->wait_for_sample(500ms).channel(0)->bus_voltage;
  EXPECT_EQ(seen, 30000);
}

TEST(EthNormalMode, KeepsTheWatchdogFedAndNeverCommandsCurrent) {
  test::RunningBoard card;
  const auto session = NormalModeSession::open(card.target(0), programs_timing::normal_mode());
  // The caller dawdles (it takes no sample) while the worker keeps cadence: until the worker
  // has published ten DOITs' worth, however long a loaded machine takes.
  ASSERT_TRUE(test::eventually(
      [&] {
        const auto latest = session->latest();
        return latest && latest->doits >= 10;
      },
      20s))
      << "the worker did not keep cadence on its own";
  const LiveStatus s = session->wait_for_sample(500ms);
  EXPECT_GE(s.doits, 10u);
  card.with_amplifier(0, 0, [&](sim::Virtual8i20& amp) {
    EXPECT_EQ(amp.amplifier().value("QSETPOINT"), 0u);
    EXPECT_EQ(amp.amplifier().value("ANGLE"), 0u);
    // On a loaded test machine the worker (or the server) can be starved past 40 ms;
    // then a bite is the machine's doing, and the gap says so.
    if (s.max_doit_gap < 30ms && s.missed_cycles == 0) {
      EXPECT_EQ(amp.amplifier().watchdog_bites(), 0u) << "max DOIT gap " << s.max_doit_gap.count() << " us";
      EXPECT_EQ(s.channel(0)->fault & 0x0001, 0) << "watchdog fault";
    }
  });
  card.server().with_card([](ethsim::VirtualBoard& c) {
    EXPECT_EQ(c.sslbp(0).mode(0), ethsim::ChannelMode::Normal);
    EXPECT_EQ(c.sslbp(0).stats().ignored_while_busy, 0u);
  });
}

TEST(EthNormalMode, FaultsShowUpInInterface1) {
  test::RunningBoard card;
  const auto session = NormalModeSession::open(card.target(0), programs_timing::normal_mode());
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { amp.world().settings().enable = false; });
  std::uint16_t fault = 0;
  for (int i = 0; i < 30 && fault == 0; ++i) fault = session->wait_for_sample(500ms).channel(0)->fault;
  EXPECT_TRUE(fault & 0x0002) << "no-enable fault, got " << fault;
}

TEST(EthNormalMode, StopSendsTheStopCommand) {
  test::RunningBoard card;
  auto session = NormalModeSession::open(card.target(0), programs_timing::normal_mode());
  session->wait_for_sample(500ms);
  session->stop();
  EXPECT_FALSE(session->running());
  card.server().with_card(
      [](ethsim::VirtualBoard& c) { EXPECT_EQ(c.sslbp(0).mode(0), ethsim::ChannelMode::Stopped); });
  session->stop();  // idempotent
  EXPECT_THROW(session->wait_for_sample(50ms), link::TimeoutError);
}

TEST(EthNormalMode, DestructionStopsToo) {
  test::RunningBoard card;
  {
    const auto session = NormalModeSession::open(card.target(0), programs_timing::normal_mode());
    session->wait_for_sample(500ms);
  }
  card.server().with_card(
      [](ethsim::VirtualBoard& c) { EXPECT_EQ(c.sslbp(0).mode(0), ethsim::ChannelMode::Stopped); });
}

TEST(EthNormalMode, SeveralChannelsOfA7i92tPort) {
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{1, 2}, {1, 5}};
  test::RunningBoard card(options);
  const auto session = NormalModeSession::open(card.address(), 1, 0x24, programs_timing::normal_mode());
  EXPECT_EQ(session->unit_number(2), 0x00012345u);
  EXPECT_EQ(session->unit_number(5), 0x00012346u);
  const LiveStatus s = session->wait_for_sample(500ms);
  ASSERT_EQ(s.channels.size(), 2u);
  EXPECT_EQ(s.channel(5)->bus_voltage, 32000);
}

TEST(EthNormalMode, ChannelThatDoesNotStartIsReported) {
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{0, 0}};
  test::RunningBoard card(options);
  try {
    NormalModeSession::open(card.address(), 0, 0x03, programs_timing::normal_mode());
    FAIL();
  } catch (const DiscoveryError& e) {
    EXPECT_NE(std::string(e.what()).find("ch 1"), std::string::npos) << e.what();
  }
}

TEST(EthNormalMode, CardThatGoesAwayFailsTheSession) {
  auto card = std::make_unique<test::RunningBoard>();
  auto options = programs_timing::normal_mode();
  options.udp.timeout = 10ms;
  const auto session = NormalModeSession::open(card->target(0), options);
  session->wait_for_sample(500ms);
  card.reset();  // the card vanishes
  EXPECT_THROW(
      {
        for (int i = 0; i < 50; ++i) session->wait_for_sample(200ms);
      },
      link::TimeoutError);
  // A sample wait can give up before the worker's own reply timeout (from measured round
  // trips, longer on a loaded host) has run out and ended it: wait for the worker.
  EXPECT_TRUE(test::eventually([&] { return !session->running(); }));
}

TEST(EthNormalMode, RefusesPeriodsThatLetTheWatchdogBite) {
  test::RunningBoard card;
  auto options = programs_timing::normal_mode();
  options.period = 30ms;
  EXPECT_THROW(NormalModeSession::open(card.target(0), options), UsageError);
}
