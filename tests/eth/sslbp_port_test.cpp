// SPDX-License-Identifier: GPL-2.0-or-later
// SslbpPort beside another host that writes COMMAND (LinuxCNC after a take-over): SSLBP
// ignores a command written while it is busy (8I20 manual, "SSLBP": COMMAND reads non-zero
// until done), and the busy command may finish before our read-back. What it leaves in DATA
// must never be taken for our command's result. The card is the virtual 7I96S, in process,
// with a clock the test moves: no thread, no socket, no timing of the host.
#include "eth/sslbp_port.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "eth/batched_opening.hpp"
#include "eth/errors.hpp"
#include "eth/transport.hpp"
#include "ethsim/virtual_8i20_remote.hpp"
#include "ethsim/virtual_board.hpp"
#include "hostmot2/hostmot2.hpp"
#include "lbp/bytes.hpp"

using namespace i20;
using namespace i20::eth;
using namespace std::chrono_literals;
namespace lbp16 = i20::lbp::lbp16;
namespace sslbp = i20::lbp::hm2::sslbp;

namespace {

// Hands each packet to the virtual card. Before every packet of ours that writes COMMAND,
// another host writes a DOIT to it (while `foreign_writes` lasts), and before every other
// packet of ours too while `foreign_writes_between` lasts; 100 us pass between packets.
class AnotherHostWritesFirst final : public Lbp16Transport {
 public:
  AnotherHostWritesFirst(ethsim::VirtualBoard& board, ethsim::Clock::time_point& t) : card_(board), t_(t) {}

  unsigned foreign_writes = 0;
  unsigned foreign_writes_between = 0;

  std::vector<lbp::Bytes> transact(std::span<const lbp16::Command> commands, Resend) override {
    const auto command = card_.sserial_registers(0).command;
    const bool writes_command = std::any_of(commands.begin(), commands.end(), [&](const lbp16::Command& c) {
      return c.word.write && c.address == command;
    });
    unsigned& budget = writes_command ? foreign_writes : foreign_writes_between;
    if (budget > 0) {
      --budget;
      card_.handle(lbp16::encode_packet(std::vector{lbp16::write_hm2(command, sslbp::doit(0x01))}), t_);
    }
    ++stats_.packets_sent;
    const auto reply = card_.handle(lbp16::encode_packet(commands), t_);
    t_ += 100us;
    return lbp16::split_reply(commands, *reply);
  }
  std::string describe() const override { return "virtual 7I96S"; }
  TransportStats stats() const override { return stats_; }

 private:
  ethsim::VirtualBoard& card_;
  ethsim::Clock::time_point& t_;
  TransportStats stats_{};
};

class EthSslbpPort : public ::testing::Test {
 protected:
  ethsim::Clock::time_point t = ethsim::Clock::time_point{} + 1h;
  std::unique_ptr<ethsim::VirtualBoard> card = make();
  AnotherHostWritesFirst bus{*card, t};

  std::unique_ptr<ethsim::VirtualBoard> make() {
    ethsim::VirtualBoardOptions options;
    options.config = ethsim::BoardConfig::preset(ethsim::BoardKind::I7i96s);
    options.remotes = [this](unsigned, unsigned ch) -> std::unique_ptr<ethsim::RemoteLbpDevice> {
      if (ch != 0) return nullptr;
      return std::make_unique<ethsim::Virtual8i20Remote>(ethsim::Virtual8i20Remote::default_options(), t);
    };
    return std::make_unique<ethsim::VirtualBoard>(std::move(options), t);
  }

  // A port whose local reads and stops wait `settle` in the packet: long enough for the other
  // host's DOIT to finish before the read-back, which is the race under test.
  SslbpPort port(std::chrono::milliseconds command_timeout, std::chrono::microseconds settle = 5ms) {
    SserialPort p;
    p.registers = card->sserial_registers(0);
    return SslbpPort(bus, p, /*timer_space=*/true,
                     SslbpOptions{.command_timeout = command_timeout,
                                  .poll_pause = std::chrono::microseconds(0),
                                  .local_settle = settle,
                                  .lost_reply_retries = 0u});
  }
};

}  // namespace

TEST_F(EthSslbpPort, ACommandIgnoredWhileAnotherRanIsWrittenAgainAndItsOwnResultReturned) {
  auto sslbp = port(2000ms);
  sslbp.stop_all();
  const auto truth = sslbp.read_local(sslbp::param::kChannels);
  ASSERT_EQ(truth, 1u) << "the 7I96S's one SSERIAL channel";
  // Now another host's DOIT holds COMMAND as each of the next reads is written (it fails on
  // the stopped channel, so its DATA is 0x01): every read still returns the parameter.
  bus.foreign_writes = 3;
  const auto ignored_before = card->sslbp(0).stats().ignored_while_busy;
  EXPECT_EQ(sslbp.read_local(sslbp::param::kChannels), truth);
  EXPECT_EQ(sslbp.read_local(sslbp::param::kMajorVersion), 0u);
  EXPECT_EQ(sslbp.read_local(sslbp::param::kMinorVersion), 40u);
  EXPECT_EQ(card->sslbp(0).stats().ignored_while_busy - ignored_before, 3u) << "the race happened";
}

TEST_F(EthSslbpPort, APortAnotherHostNeverLeavesIsAnErrorNotItsResult) {
  auto sslbp = port(20ms);
  sslbp.stop_all();
  bus.foreign_writes = 1'000'000;
  try {
    const auto data = sslbp.read_local(sslbp::param::kChannels);
    FAIL() << "returned " << unsigned{data} << ", the other host's DATA";
  } catch (const ForeignHostError& e) {
    EXPECT_NE(std::string(e.what()).find("another host keeps the port busy"), std::string::npos) << e.what();
  }
}

// The opening packs the stop and the parameter reads into one packet (batched_opening.cpp):
// another host's DOIT holding COMMAND at its first write must not hand its DATA to the first
// step either.
TEST_F(EthSslbpPort, TheBatchedOpeningBesideAnotherHostReadsTheTrueParameters) {
  auto sslbp = port(2000ms, 50ms);  // a DOIT on a channel in setup mode takes milliseconds
  ASSERT_EQ(sslbp.start_setup(0x01), 0u);
  bus.foreign_writes = 1;
  const SslbpParameters p = stop_and_read_parameters(sslbp);
  EXPECT_EQ(card->sslbp(0).mode(0), ethsim::ChannelMode::Stopped)
      << "the stop was ignored, yet taken as done";
  EXPECT_EQ(p.channels, 1u);
  EXPECT_EQ(p.version(), "0.40");
  EXPECT_EQ(p.clock_hz, 100'000'000u);
  EXPECT_EQ(bus.foreign_writes, 0u) << "the other host wrote first";
}

// Our local read finishes after its own packet (no WaituS in it); before the read that finds
// COMMAND idle, another host's DOIT runs and leaves its DATA (0x01: the stopped channel
// failed). The card's count of the packets it received shows the stranger, so the read is run
// again and returns the parameter, not the DOIT's result ("SSLBP 0.0, 0 channels" in a scan
// beside LinuxCNC).
TEST_F(EthSslbpPort, AResultReadAfterAnotherHostsPacketIsNotTakenForOurs) {
  auto sslbp = port(2000ms, 0us);
  sslbp.stop_all();
  bus.foreign_writes_between = 1;
  EXPECT_EQ(sslbp.read_local(sslbp::param::kMinorVersion), 40u);
  EXPECT_EQ(bus.foreign_writes_between, 0u) << "the other host's DOIT ran";
}

// A command that may not run twice (a start) cannot be tried again: another host's packet
// while it ran is an error naming that host, not a result.
TEST_F(EthSslbpPort, ACommandThatCannotRunTwiceDisturbedByAnotherHostIsAnError) {
  auto sslbp = port(2000ms, 0us);
  sslbp.stop_all();
  bus.foreign_writes_between = 1;
  try {
    sslbp.run({}, sslbp::start_setup(0x01), {}, /*repeatable=*/false);
    FAIL() << "a result taken after another host's packet";
  } catch (const ForeignHostError& e) {
    EXPECT_NE(std::string(e.what()).find("another host sent 1 packet(s)"), std::string::npos) << e.what();
  }
}
