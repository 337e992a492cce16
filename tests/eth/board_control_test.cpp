// SPDX-License-Identifier: GPL-2.0-or-later
// The simulator's control language with a virtual Ethernet card: per-channel prefixes,
// "all", and the LinuxCNC stand-in (ethsim/board_control.hpp).
#include "ethsim/board_control.hpp"

#include <gtest/gtest.h>

#include "eth/udp_client.hpp"
#include "fixtures.hpp"
#include "lbp16/lbp16.hpp"
#include "link/link.hpp"
#include "sim/error.hpp"

using namespace i20;
using namespace std::chrono_literals;

namespace {

ethsim::ServerOptions four_on_a_7i92t() {
  ethsim::ServerOptions o;
  o.card = ethsim::BoardKind::I7i92t;
  o.amplifiers = {{0, 0}, {0, 1}, {0, 2}, {1, 7}};
  return o;
}

double busv(test::RunningBoard& card, unsigned port, unsigned channel) {
  return card.with_amplifier(port, channel,
                             [](sim::Virtual8i20& a) { return a.world().settings().bus_volts; });
}

}  // namespace

TEST(EthBoardControl, APrefixNamesTheChannelAndPlainLinesGoToTheFirst8I20) {
  test::RunningBoard card(four_on_a_7i92t());
  auto& server = card.server();
  EXPECT_EQ(ethsim::apply_board_control(server, "ch 2 busv 24"), "ok");
  EXPECT_EQ(ethsim::apply_board_control(server, "channel 1 busv 48"), "ok");
  EXPECT_EQ(ethsim::apply_board_control(server, "port 1 ch 7 busv 100"), "ok");
  EXPECT_EQ(ethsim::apply_board_control(server, "busv 300"), "ok");
  EXPECT_DOUBLE_EQ(busv(card, 0, 0), 300.0);
  EXPECT_DOUBLE_EQ(busv(card, 0, 1), 48.0);
  EXPECT_DOUBLE_EQ(busv(card, 0, 2), 24.0);
  EXPECT_DOUBLE_EQ(busv(card, 1, 7), 100.0);
  EXPECT_EQ(ethsim::apply_board_control(server, "ch 2 get UNITNUMBER"), std::to_string(0x00012345 + 2));
  const auto all = ethsim::apply_board_control(server, "all enable off");
  EXPECT_EQ(all, "p0c0: ok; p0c1: ok; p0c2: ok; p1c7: ok");
  EXPECT_NE(ethsim::apply_board_control(server, "amplifiers").find("port 1 ch 7"), std::string::npos);
  EXPECT_EQ(ethsim::apply_board_control(server, "# a comment"), "");
}

TEST(EthBoardControl, MistakesSayWhatIsExpected) {
  test::RunningBoard card(four_on_a_7i92t());
  auto& server = card.server();
  EXPECT_THROW(ethsim::apply_board_control(server, "ch 5 busv 24"), sim::ControlError) << "no 8I20 on ch 5";
  EXPECT_THROW(ethsim::apply_board_control(server, "ch two busv 24"), sim::ControlError);
  EXPECT_THROW(ethsim::apply_board_control(server, "ch 1"), sim::ControlError);
  EXPECT_THROW(ethsim::apply_board_control(server, "port 1 7 busv 3"), sim::ControlError);
  EXPECT_THROW(ethsim::apply_board_control(server, "ch 1 bogus 3"), sim::ControlError);
  EXPECT_THROW(ethsim::apply_board_control(server, "host on 99"), sim::ControlError);
  EXPECT_THROW(ethsim::apply_board_control(server, "host on port 4"), sim::ControlError);
  try {
    ethsim::apply_board_control(server, "ch 6 temp 50");
  } catch (const sim::ControlError& e) {
    EXPECT_NE(std::string(e.what()).find("channel 6"), std::string::npos) << e.what();
  }
}

TEST(EthBoardControl, TheHostStandInStartsRunsAndStops) {
  test::RunningBoard card;
  auto& server = card.server();
  EXPECT_EQ(ethsim::apply_board_control(server, "host"), "host: none (the card is idle)");
  EXPECT_EQ(ethsim::apply_board_control(server, "host on 2")
                .rfind("ok: normal mode on SSERIAL port 0 ch 0, every 2 ms", 0),
            0u);
  // The stand-in runs on its own thread: wait until it has started the channel and run DOITs.
  const auto running = [&] {
    const bool normal = server.with_card(
        [](ethsim::VirtualBoard& c) { return c.sslbp(0).mode(0) == ethsim::ChannelMode::Normal; });
    return normal && ethsim::apply_board_control(server, "host").find(" 0 DOITs") == std::string::npos;
  };
  EXPECT_TRUE(test::eventually(running)) << ethsim::apply_board_control(server, "host");
  EXPECT_EQ(ethsim::apply_board_control(server, "host off"), "ok");
  server.with_card(
      [](ethsim::VirtualBoard& c) { EXPECT_EQ(c.sslbp(0).mode(0), ethsim::ChannelMode::Stopped); });
}

// A lossy link (card loss RATE [SEED]): the card never sees a lost datagram, so its sender
// gets no reply; at 0 every datagram is answered again. Rates outside 0..1 are refused.
TEST(EthBoardControl, ADatagramLostOnTheWayToTheCardGetsNoReply) {
  test::RunningBoard card;
  auto& server = card.server();
  const lbp::lbp16::Command cookie = lbp::lbp16::read_hm2(0x0100);
  const auto ask = [&](std::chrono::milliseconds wait) {
    eth::UdpClient client(card.address().ip, card.address().port,
                          eth::UdpOptions{.timeout = wait, .max_timeout = wait, .retries = 0});
    return client.transact(std::span(&cookie, 1));
  };
  EXPECT_EQ(ethsim::apply_board_control(server, "card loss 1"), "ok");
  EXPECT_THROW(ask(100ms), link::TimeoutError);
  EXPECT_EQ(ethsim::apply_board_control(server, "card loss 0 7"), "ok");
  EXPECT_EQ(ask(5000ms).size(), 1u);
  EXPECT_THROW(ethsim::apply_board_control(server, "card loss 1.5"), sim::ControlError);
  EXPECT_THROW(ethsim::apply_board_control(server, "card loss some"), sim::ControlError);
}
