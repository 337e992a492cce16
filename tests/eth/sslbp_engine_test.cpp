// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual SSLBP processor in front of a virtual 8I20, driven through the card's
// registers with a test-controlled clock (8I20 manual, "SSLBP").
#include "ethsim/sslbp_engine.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "ethsim/virtual_8i20_remote.hpp"
#include "ethsim/virtual_board.hpp"

using namespace i20;
using namespace i20::ethsim;
using namespace std::chrono_literals;
namespace lbp16 = i20::lbp::lbp16;
namespace sslbp = i20::lbp::hm2::sslbp;

namespace {

constexpr std::uint16_t kCommand = 0x5B00, kData = 0x5C00, kCs = 0x5D00, kIf0 = 0x5E00, kIf1 = 0x5F00;

class EthSslbpEngine : public ::testing::Test {
 protected:
  Clock::time_point t = Clock::time_point{} + 1h;
  sim::Virtual8i20* amp = nullptr;  // the last amplifier built
  std::unique_ptr<VirtualBoard> card = make(BoardKind::I7i96s, {0});

  std::unique_ptr<VirtualBoard> make(BoardKind kind, std::vector<unsigned> channels_with_8i20) {
    VirtualBoardOptions options;
    options.config = BoardConfig::preset(kind);
    options.remotes = [this, channels_with_8i20](unsigned, unsigned ch) -> std::unique_ptr<RemoteLbpDevice> {
      if (std::find(channels_with_8i20.begin(), channels_with_8i20.end(), ch) == channels_with_8i20.end())
        return nullptr;
      auto remote = std::make_unique<Virtual8i20Remote>(Virtual8i20Remote::default_options(), t);
      amp = &remote->device();
      return remote;
    };
    return std::make_unique<VirtualBoard>(std::move(options), t);
  }

  std::uint32_t read(std::uint16_t address) {
    const std::vector<lbp16::Command> c{lbp16::read_hm2(address)};
    return static_cast<std::uint32_t>(
        lbp::read_le(lbp16::split_reply(c, *card->handle(lbp16::encode_packet(c), t))[0]));
  }
  void write(std::uint16_t address, std::uint32_t value) {
    card->handle(lbp16::encode_packet(std::vector{lbp16::write_hm2(address, value)}), t);
  }
  // Writes COMMAND and lets time pass until it clears; returns DATA.
  std::uint8_t command(std::uint32_t value) {
    write(kCommand, value);
    for (int i = 0; i < 1000 && read(kCommand) != 0; ++i) t += 50us;
    EXPECT_EQ(read(kCommand), 0u);
    return static_cast<std::uint8_t>(read(kData));
  }
};

}  // namespace

TEST_F(EthSslbpEngine, CommandsTakeTimeAndResultsAppearOnlyWhenDone) {
  command(sslbp::stop());
  EXPECT_EQ(command(sslbp::start_setup(0x01)), 0);
  write(kCs, sslbp::passthrough_cs(0x46, 2344));  // read UNITNUMBER (4 bytes)
  write(kIf0, 0);
  write(kCommand, sslbp::doit(0x01));
  EXPECT_EQ(read(kCommand), sslbp::doit(0x01));  // the serial exchange has not happened yet
  EXPECT_EQ(read(kIf0), 0x00012345u);            // still the unit number from the start...
  t += 5ms;
  EXPECT_EQ(read(kCommand), 0u);
  EXPECT_EQ(read(kData), 0u);
  EXPECT_EQ(read(kIf0), 0x00012345u);  // ... now the passthrough's answer (the same number)
  EXPECT_EQ(read(kCs) >> 24, sslbp::kRemoteMode8i20);
}

TEST_F(EthSslbpEngine, CommandWrittenWhileBusyIsIgnored) {
  command(sslbp::stop());
  write(kCommand, sslbp::start_setup(0x01));
  write(kCommand, sslbp::read_local(sslbp::param::kChannels));
  EXPECT_EQ(read(kCommand), sslbp::start_setup(0x01));
  EXPECT_EQ(card->sslbp(0).stats().ignored_while_busy, 1u);
}

TEST_F(EthSslbpEngine, SetupStartReportsNameAndUnitAndFailedChannels) {
  card = make(BoardKind::I7i92t, {1});
  EXPECT_EQ(command(sslbp::start_setup(0x03)), 0x01);  // channel 0 is empty
  EXPECT_EQ(read(kIf1 + 4), sslbp::kName8i20);
  EXPECT_EQ(read(kIf0 + 4), 0x00012345u);
  const sslbp::ChannelStatus empty{read(kCs)};
  EXPECT_TRUE(empty.timed_out());
  EXPECT_TRUE(empty.status() & sslbp::ChannelStatus::kNoRemoteId);
  // Only a stop clears the sticky error byte.
  EXPECT_EQ(command(sslbp::start_setup(0x01)), 0x01);
  command(sslbp::stop());
  EXPECT_EQ(read(kCs), 0u);
}

TEST_F(EthSslbpEngine, ResetBitHoldsTheProcessor) {
  command(sslbp::start_setup(0x01));
  write(kCommand, sslbp::kReset | sslbp::kStop);
  EXPECT_EQ(read(kCommand), sslbp::kReset | sslbp::kStop);
  EXPECT_EQ(card->sslbp(0).mode(0), ChannelMode::Stopped);
  EXPECT_EQ(command(sslbp::stop()), 0);  // released: runs normally again
}

TEST_F(EthSslbpEngine, LocalParametersAndWrites) {
  EXPECT_EQ(command(sslbp::read_local(sslbp::param::kChannels)), 1);
  EXPECT_EQ(command(sslbp::read_local(sslbp::param::kClock + 3)), 100'000'000u >> 24);
  write(kData, 0x5A);
  command(sslbp::write_local(0x300));
  EXPECT_EQ(command(sslbp::read_local(0x300)), 0x5A);
}

TEST_F(EthSslbpEngine, NormalStartChattersUntilTheFirstDoitThenDoitFeedsTheWatchdog) {
  command(sslbp::stop());
  EXPECT_EQ(command(sslbp::start_normal(0x01)), 0);
  EXPECT_EQ(read(kIf0), 0x00012345u);  // unit number before the first DOIT
  // 200 ms without DOIT: SSLBP's cookie chatter keeps the 8I20's 40 ms watchdog fed.
  for (int i = 0; i < 40; ++i) {
    t += 5ms;
    card->advance(t);
  }
  EXPECT_EQ(amp->amplifier().watchdog_bites(), 0u);
  EXPECT_GT(card->sslbp(0).stats().chatter, 15u);
  // DOITs every 10 ms: BUSV/TEMPERATURE in INTERFACE0, FAULT/STATUS in INTERFACE1
  // (8I20 manual, 8I20 SPECIFIC INTERFACE REGISTER 0/1 DEFINITIONS).
  for (int i = 0; i < 10; ++i) {
    write(kIf0, 0);
    EXPECT_EQ(command(sslbp::doit(0x01)), 0);
    t += 10ms;
  }
  EXPECT_EQ(read(kIf0) >> 16, 32000u);  // "Bus voltage in 10s of mV": 320 V
  EXPECT_EQ(read(kIf0) & 0xFFFF, 35u);  // "Card Temperature in oC": whole degrees, not 0.01 C
  EXPECT_EQ(read(kIf1) >> 16, 0u);
  EXPECT_EQ(amp->amplifier().watchdog_bites(), 0u);
  // After the first DOIT there is no more chatter: stop the DOITs and the watchdog bites.
  for (int i = 0; i < 20; ++i) {
    t += 5ms;
    card->advance(t);
  }
  EXPECT_GE(amp->amplifier().watchdog_bites(), 1u);
  write(kIf0, 0);
  command(sslbp::doit(0x01));
  EXPECT_TRUE((read(kIf1) >> 16) & 0x0001) << "watchdog fault bit";
  EXPECT_TRUE(sslbp::ChannelStatus{read(kCs)}.status() & sslbp::ChannelStatus::kRemoteFault);
}

TEST_F(EthSslbpEngine, DoitToAStoppedChannelFails) {
  command(sslbp::stop());
  EXPECT_EQ(command(sslbp::doit(0x01)), 0x01);
  EXPECT_TRUE(sslbp::ChannelStatus{read(kCs)}.status() & sslbp::ChannelStatus::kNotReady);
}
