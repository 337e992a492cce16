// SPDX-License-Identifier: GPL-2.0-or-later
// SslbpPassthroughLink: 8I20 LBP commands through SSLBP's setup-mode passthrough of the
// virtual card, over UDP on loopback.
#include "eth/passthrough_link.hpp"

#include <gtest/gtest.h>

#include "eth/errors.hpp"
#include "fixtures.hpp"
#include "programs_timing.hpp"

using namespace i20;
using namespace i20::eth;
using namespace std::chrono_literals;
using lbp::DataSize;

namespace {

// Public addresses (docs/facts.md section 2) and the simulator's map for the RAM ones.
constexpr std::uint16_t kUnitNumber = 2344;
constexpr std::uint16_t kSwRevision = 2164;
constexpr std::uint16_t kNvKqp = 10;
constexpr std::uint16_t kFaultMask = 0x0806;

std::uint64_t value(const lbp::Bytes& bytes) {
  return lbp::read_le(bytes);
}

}  // namespace

TEST(EthPassthrough, OpensTheChannelAndFindsThe8i20) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  EXPECT_EQ(link->remote().name, "8I20");
  EXPECT_EQ(link->remote().unit_number, 0x00012345u);
  EXPECT_EQ(link->board().card_name, "7I96S");
  EXPECT_EQ(link->describe(), "eth " + card.address().describe() + " ch 0");
  EXPECT_FALSE(link->notes().empty());
  card.server().with_card(
      [](ethsim::VirtualBoard& c) { EXPECT_EQ(c.sslbp(0).mode(0), ethsim::ChannelMode::Setup); });
}

TEST(EthPassthrough, ReadsWordsAndLongsAndLocalRegisters) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const std::vector<lbp::Command> batch{
      lbp::read(kUnitNumber, DataSize::Four), lbp::read(kSwRevision, DataSize::Two),
      lbp::local_read(lbp::local::kGetCookie), lbp::local_read(lbp::local::kGetCardName0)};
  const auto replies = link->execute(batch);
  ASSERT_EQ(replies.size(), 4u);
  EXPECT_EQ(value(replies[0]), 0x00012345u);
  EXPECT_EQ(value(replies[1]), 0xE120u);
  EXPECT_EQ(replies[2], lbp::Bytes{0x5A});
  EXPECT_EQ(replies[3], lbp::Bytes{'8'});
}

TEST(EthPassthrough, ParameterReadCostsAtMostTwoRoundTrips) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const auto sent_before = link->transport_stats().packets_sent;
  for (int i = 0; i < 20; ++i) link->execute_one(lbp::read(kSwRevision, DataSize::Two));
  EXPECT_EQ(link->stats().commands, 20u);
  EXPECT_LE(link->stats().max_round_trips, 2u);
  // With the WaituS in the packet the estimate normally holds: one round trip each.
  EXPECT_EQ(link->transport_stats().packets_sent - sent_before, link->stats().round_trips);
  EXPECT_LE(link->stats().round_trips, 22u);
  RecordProperty("round_trips_for_20_reads", static_cast<int>(link->stats().round_trips));
}

TEST(EthPassthrough, ParameterWriteAndNvWriteRoundTrips) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  link->execute_one(lbp::write(kFaultMask, DataSize::Two, 0xFFFF));
  EXPECT_LE(link->stats().max_round_trips, 2u);
  RecordProperty("round_trips_ram_write", static_cast<int>(link->stats().round_trips));
  const auto before = link->stats().round_trips;
  const std::vector<lbp::Command> nv{lbp::set_nv_access(lbp::local::NvAccess::Eeprom),
                                     lbp::write(kNvKqp, DataSize::Two, 60),
                                     lbp::set_nv_access(lbp::local::NvAccess::Ram)};
  link->execute(nv);
  EXPECT_LE(link->stats().max_round_trips, 2u);  // the EEPROM write time is part of the estimate
  RecordProperty("round_trips_nv_write_sequence", static_cast<int>(link->stats().round_trips - before));
}

TEST(EthPassthrough, WithoutTheTimerSpaceItPollsUntilCommandClears) {
  ethsim::ServerOptions options;
  options.config = ethsim::BoardConfig::preset(ethsim::BoardKind::I7i96s);
  options.config->lbp16_version = 2;                          // no space 4: no WaituS
  options.sslbp.processing = std::chrono::microseconds(300);  // a slow SSLBP
  test::RunningBoard card(options);
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  EXPECT_EQ(value(link->execute_one(lbp::read(kUnitNumber, DataSize::Four))), 0x00012345u);
  EXPECT_GE(link->stats().max_round_trips, 2u);  // COMMAND was still busy at the first read-back
  card.server().with_card(
      [](ethsim::VirtualBoard& c) { EXPECT_EQ(c.sslbp(0).stats().ignored_while_busy, 0u); });
}

TEST(EthPassthrough, WritesRamAndReadsItBack) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  link->execute_one(lbp::write(kFaultMask, DataSize::Two, 0xFEFF));
  EXPECT_EQ(value(link->execute_one(lbp::read(kFaultMask, DataSize::Two))), 0xFEFFu);
  EXPECT_EQ(
      card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { return amp.amplifier().value("FAULTMASK"); }),
      0xFEFFu);
}

TEST(EthPassthrough, NvModeWritesTheEepromThroughCs0xEC) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const std::vector<lbp::Command> batch{
      lbp::set_nv_access(lbp::local::NvAccess::Eeprom), lbp::write(kNvKqp, DataSize::Two, 77),
      lbp::read(kNvKqp, DataSize::Two), lbp::set_nv_access(lbp::local::NvAccess::Ram),
      lbp::local_read(lbp::local::kGetNvAccess)};
  const auto replies = link->execute(batch);
  EXPECT_EQ(value(replies[2]), 77u);
  EXPECT_EQ(replies[4], lbp::Bytes{0});
  EXPECT_EQ(card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { return amp.amplifier().value("NVKQP"); }),
            77u);
  // NV values take effect only after a reset: KQP is still the default.
  EXPECT_EQ(card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { return amp.amplifier().value("KQP"); }),
            50u);
}

TEST(EthPassthrough, UnsupportedCommandsAreRefusedWithTheirIndex) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const std::vector<lbp::Command> batch{lbp::read(kSwRevision, DataSize::Two),
                                        lbp::read(0x0816, DataSize::Eight)};
  try {
    link->execute(batch);
    FAIL();
  } catch (const link::UnsupportedCommand& e) {
    EXPECT_EQ(e.completed(), 1u);
    EXPECT_NE(std::string(e.what()).find("8-byte"), std::string::npos) << e.what();
  }
  EXPECT_THROW(link->execute_one(lbp::rpc(1, {}, 4)), link::UnsupportedCommand);
  EXPECT_NO_THROW(link->execute_one(lbp::read(kSwRevision, DataSize::Two)));
}

TEST(EthPassthrough, SilentRemoteIsATimeoutInWords) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) {
    sim::Injection mute;
    mute.answer_limit = 0;
    amp.set_injection(mute);
  });
  const std::vector<lbp::Command> batch{lbp::local_read(lbp::local::kGetCookie),
                                        lbp::read(kSwRevision, DataSize::Two)};
  try {
    link->execute(batch);
    FAIL();
  } catch (const link::TimeoutError& e) {
    EXPECT_EQ(e.completed(), 0u);
    EXPECT_NE(std::string(e.what()).find("timeout"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("eth 127.0.0.1"), std::string::npos) << e.what();
  }
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { amp.set_injection(sim::Injection{}); });
  EXPECT_EQ(value(link->execute_one(lbp::read(kSwRevision, DataSize::Two))), 0xE120u);
}

TEST(EthPassthrough, CorruptedRepliesAreCrcErrors) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) {
    sim::Injection corrupt;
    corrupt.corrupt_rate = 1.0;
    amp.set_injection(corrupt);
  });
  try {
    link->execute_one(lbp::read(kSwRevision, DataSize::Two));
    FAIL();
  } catch (const link::CrcError& e) {
    EXPECT_NE(std::string(e.what()).find("CRC error"), std::string::npos) << e.what();
  }
}

TEST(EthPassthrough, EmptyChannelIsADiscoveryError) {
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{0, 0}};
  test::RunningBoard card(options);
  try {
    SslbpPassthroughLink::open(card.target(2), programs_timing::passthrough());
    FAIL();
  } catch (const DiscoveryError& e) {
    EXPECT_NE(std::string(e.what()).find("no remote answered"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SslbpPassthroughLink::open(card.target(0, 2), programs_timing::passthrough()),
               DiscoveryError);  // no SSERIAL port 2
  EXPECT_NO_THROW(SslbpPassthroughLink::open(card.target(0, 0), programs_timing::passthrough()));
}

TEST(EthPassthrough, NoCardAtTheAddressTimesOut) {
  // Nothing listens on this port: the open fails with a timeout, quickly.
  test::ScriptedBoard silent([](const lbp::Bytes&, const auto&, test::ScriptedBoard::Sockets) {});
  auto options = programs_timing::passthrough();
  options.udp.timeout = 20ms;
  EXPECT_THROW(
      SslbpPassthroughLink::open(make_target("127.0.0.1:" + std::to_string(silent.port()), 0), options),
      link::TimeoutError);
}
