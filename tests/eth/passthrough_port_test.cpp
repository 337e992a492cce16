// SPDX-License-Identifier: GPL-2.0-or-later
// PassthroughPort: many LBP commands per UDP packet through SSLBP's setup-mode
// passthrough, a check that each DOIT completed (COMMAND back to 0, 8I20 manual "DOIT"),
// polling and replays when one did not, and one DOIT serving several channels of a port.
// The virtual card models SSLBP timing (a DOIT takes the remote's serial time plus
// processing; WaituS holds the reply), so a wait that is too short shows here.
#include "eth/passthrough_port.hpp"

#include <gtest/gtest.h>

#include <thread>

#include "eth/errors.hpp"
#include "eth/normal_mode.hpp"
#include "eth/passthrough_link.hpp"
#include "fixtures.hpp"
#include "lbp/local.hpp"
#include "programs_timing.hpp"

using namespace i20;
using namespace i20::eth;
using namespace std::chrono_literals;
using lbp::DataSize;
namespace L = lbp::local;

namespace {

// Public addresses (docs/facts.md section 2) and the simulator's map for the RAM ones.
constexpr std::uint16_t kUnitNumber = 2344;
constexpr std::uint16_t kSwRevision = 2164;
constexpr std::uint16_t kMaxCurrent = 0x08E8;
constexpr std::uint16_t kNvKqp = 10;
constexpr std::uint16_t kNvBrakeOnV = 40;
constexpr std::uint16_t kFault = 0x0800;
constexpr std::uint16_t kStatus = 0x0802;
constexpr std::uint16_t kFaultMask = 0x0806;
constexpr std::uint16_t kBrakeOnV = 0x082C;

std::uint64_t value(const lbp::Bytes& bytes) {
  return lbp::read_le(bytes);
}

// What i20 dump sends: working reads, then NV reads inside NV access mode with a check.
std::vector<lbp::Command> dump_like() {
  std::vector<lbp::Command> batch{lbp::read(kSwRevision, DataSize::Two),
                                  lbp::read(kUnitNumber, DataSize::Four)};
  for (std::uint16_t a = 0x0800; a < 0x0830; a += 2) batch.push_back(lbp::read(a, DataSize::Two));
  batch.push_back(lbp::set_nv_access(L::NvAccess::Eeprom));
  for (std::uint16_t a = 2; a <= 42; a += 4) batch.push_back(lbp::read(a, DataSize::Two));
  batch.push_back(lbp::local_read(L::kGetNvAccess));
  batch.push_back(lbp::set_nv_access(L::NvAccess::Ram));
  return batch;
}

// The NV write with its verify as one batch.
std::vector<lbp::Command> nv_write(std::uint16_t address, std::uint16_t v) {
  return {lbp::set_nv_access(L::NvAccess::Eeprom), lbp::local_read(L::kGetNvAccess),
          lbp::write(address, DataSize::Two, v),   lbp::read(address, DataSize::Two),
          lbp::local_read(L::kGetNvAccess),        lbp::set_nv_access(L::NvAccess::Ram)};
}

std::uint64_t packets(const SslbpPassthroughLink& link) {
  return link.transport_stats().packets_sent;
}

// The device layer's first batch reads the NV access and RPC memory modes (Amp8i20::info);
// the port learns them from it, as it does in every i20 command.
void read_modes(SslbpPassthroughLink& link) {
  link.execute(std::vector{lbp::local_read(L::kGetNvAccess), lbp::local_read(L::kGetRpcMemAccess)});
}

std::uint64_t ignored_doits(test::RunningBoard& card) {
  return card.server().with_card(
      [](ethsim::VirtualBoard& c) { return c.sslbp(0).stats().ignored_while_busy; });
}

// The programs' passthrough, but allowed to resend a packet whose reply was lost (ops sends
// 0 and repeats the exchange itself): the port's own resend, tested here.
PassthroughOptions resending() {
  auto options = programs_timing::passthrough();
  options.lost_packet_resends = 2u;
  return options;
}

// Forwards to a UdpClient; the reply of the chosen transaction is "lost" after the card
// executed the packet.
class LosingTransport final : public Lbp16Transport {
 public:
  LosingTransport(const HostPort& host_port, std::uint64_t lose)
      : inner_(host_port.ip, host_port.port, programs_timing::udp()), lose_(lose) {}
  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands, Resend resend) override {
    auto reply = inner_.transact(commands, resend);
    if (++count_ == lose_) throw link::TimeoutError("reply lost (test)");
    return reply;
  }
  std::string describe() const override { return inner_.describe(); }
  TransportStats stats() const override { return inner_.stats(); }
  void lose(std::uint64_t at) { lose_ = count_ + at; }

 private:
  UdpClient inner_;
  std::uint64_t lose_;
  std::uint64_t count_ = 0;
};

}  // namespace

TEST(EthBatching, ADumpIsOneRoundTripWithEveryValueRight) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  read_modes(*link);
  const auto before = packets(*link);
  const auto doits_before = link->stats().doits;
  const auto batch = dump_like();
  const auto r = link->execute(batch);
  EXPECT_EQ(packets(*link) - before, 1u) << batch.size() << " commands";
  EXPECT_EQ(value(r[0]), 0xE120u);
  EXPECT_EQ(value(r[1]), 0x00012345u);
  EXPECT_EQ(value(r[2 + (0x0808 - 0x0800) / 2]), 32000u) << "BUSV";
  EXPECT_EQ(value(r[r.size() - 2]), 1u) << "still in NV mode at the end of the reads";
  EXPECT_EQ(value(r[2 + 24 + 1 + 10]), 34000u) << "NVBRAKEOFFV (EEPROM 42)";
  EXPECT_EQ(link->stats().doits - doits_before, batch.size());
  EXPECT_EQ(link->stats().late_doits, 0u);
  EXPECT_EQ(ignored_doits(card), 0u);
}

// Until a read of 0xCC says which NV access mode the 8I20 is in, an 0xEC cannot follow the
// reads before it in one packet: were one of those late and the 0xEC run in the race, the
// replay could not restore a mode nobody knows. The opening reads no mode of its own (issue
// 18 item 5); the port learns it from the first 0xCC read it carries (the test above) or
// from the 0xEC steps it ran.
TEST(EthBatching, AnNvModeNobodyHasReadOrSetSplitsThePacketAtTheFirst0xEC) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  auto before = packets(*link);
  const auto batch = dump_like();
  const auto first = link->execute(batch);
  EXPECT_EQ(packets(*link) - before, 2u) << "the 0xEC opens a packet of its own";
  EXPECT_EQ(value(first[2 + (0x0808 - 0x0800) / 2]), 32000u) << "BUSV";
  EXPECT_EQ(value(first[2 + 24 + 1 + 10]), 34000u) << "NVBRAKEOFFV (EEPROM 42)";
  before = packets(*link);
  const auto again = link->execute(batch);
  EXPECT_EQ(packets(*link) - before, 1u) << "its 0xEC steps made the mode known";
  EXPECT_EQ(again, first);
}

TEST(EthBatching, NvWriteWithVerifyIsOneRoundTripAndOneEepromWrite) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const auto writes = card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.stats().eeprom_writes; });
  const auto before = packets(*link);
  const auto batch = nv_write(kNvKqp, 61);
  const auto r = link->execute(batch);
  // The EEPROM write waits inside the packet (WaituS); the read-back follows in it.
  EXPECT_EQ(packets(*link) - before, 1u);
  EXPECT_EQ(link->stats().late_doits, 0u);
  EXPECT_EQ(value(r[1]), 1u);
  EXPECT_EQ(value(r[3]), 61u);
  EXPECT_EQ(value(r[4]), 1u);
  card.with_amplifier(0, 0, [&](sim::Virtual8i20& a) {
    EXPECT_EQ(a.amplifier().value("NVKQP"), 61u);
    EXPECT_EQ(a.stats().eeprom_writes, writes + 1);
  });
  EXPECT_EQ(value(link->execute_one(lbp::local_read(L::kGetNvAccess))), 0u) << "NV mode left";
}

TEST(EthBatching, WritesAndReadBacksInOneBatch) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const std::vector<lbp::Command> batch{lbp::write(kFaultMask, DataSize::Two, 0xFEFF),
                                        lbp::read(kFaultMask, DataSize::Two),
                                        lbp::write(kBrakeOnV, DataSize::Two, 30001),
                                        lbp::read(kBrakeOnV, DataSize::Two),
                                        lbp::read(kFault, DataSize::Two),
                                        lbp::write(kBrakeOnV, DataSize::Two, 30002),
                                        lbp::read(kBrakeOnV, DataSize::Two)};
  const auto r = link->execute(batch);
  EXPECT_EQ(value(r[1]), 0xFEFFu);
  EXPECT_EQ(value(r[3]), 30001u);
  EXPECT_EQ(value(r[6]), 30002u);
  // A write after a read of the same channel opens a new packet (a replayed read must
  // not see a write that ran early): write, read | write, read, read | write, read.
  EXPECT_LE(link->stats().round_trips, 3u);
}

TEST(EthBatching, ASlowSslbpIsCaughtAndTheResultsStayRight) {
  // Every DOIT takes far longer than its WaituS: the read-back finds COMMAND busy, SSLBP
  // ignores the DOITs written after it, and the link polls and replays.
  ethsim::ServerOptions options;
  options.sslbp.processing = std::chrono::microseconds(400);
  test::RunningBoard card(options);
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const auto batch = dump_like();
  const auto r = link->execute(batch);
  EXPECT_EQ(value(r[0]), 0xE120u);
  EXPECT_EQ(value(r[2 + (0x0808 - 0x0800) / 2]), 32000u);
  EXPECT_EQ(value(r[2 + 24 + 1 + 10]), 34000u);
  EXPECT_EQ(value(r[r.size() - 2]), 1u);
  EXPECT_GT(link->stats().late_doits, 0u);
  EXPECT_GT(link->stats().slack.count(), 0) << "later WaituS grew";
  EXPECT_GT(link->stats().replays, 0u);
  EXPECT_GT(ignored_doits(card), 0u) << "the virtual card did ignore the DOITs written while busy";
  EXPECT_EQ(value(link->execute_one(lbp::local_read(L::kGetNvAccess))), 0u) << "NV mode left";
}

TEST(EthBatching, LateDoitsAreReplayedOnlyAsOftenAsTheCallerAllows) {
  // The replay bound is the caller's (PassthroughOptions::max_replays, set by
  // ops/core/timing.hpp): with none allowed, the first late DOIT ends the exchange with a
  // timeout that says why, instead of a replay.
  ethsim::ServerOptions options;
  options.sslbp.processing = std::chrono::microseconds(400);
  test::RunningBoard card(options);
  auto strict = programs_timing::passthrough();
  strict.max_replays = 0;
  const auto link = SslbpPassthroughLink::open(card.target(0), strict);
  try {
    link->execute(dump_like());
    FAIL() << "a late DOIT was replayed although no replay was allowed";
  } catch (const link::TimeoutError& e) {
    EXPECT_NE(std::string(e.what()).find("keep finishing later"), std::string::npos) << e.what();
  }
  EXPECT_GT(link->stats().late_doits, 0u);
}

// A slice of the RPC table as the device layer reads it (Amp8i20::read_rpc_table): RPC
// memory access on, the reads, off again and the check. One packet: the 0xEA that turns the
// mode off may follow the reads, because a replay's bracket turns it on again. With a slow
// SSLBP (late DOITs, replays, DOITs run in the race) every word is still the table's.
std::vector<lbp::Command> rpc_slice(std::uint16_t bytes) {
  std::vector<lbp::Command> batch{lbp::local_write(L::kSetRpcMemAccess, 1)};
  for (std::uint16_t a = 0; a < bytes; a += 4) batch.push_back(lbp::read(a, DataSize::Four));
  batch.push_back(lbp::local_write(L::kSetRpcMemAccess, 0));
  batch.push_back(lbp::local_read(L::kGetRpcMemAccess));
  return batch;
}

void expect_the_table(test::RunningBoard& card, const std::vector<lbp::Bytes>& r, std::uint16_t bytes) {
  const lbp::Bytes table = card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.rpc_table(); });
  ASSERT_GE(table.size(), bytes);
  lbp::Bytes read;
  for (std::size_t i = 1; i + 2 < r.size(); ++i) read.insert(read.end(), r[i].begin(), r[i].end());
  EXPECT_EQ(read, lbp::Bytes(table.begin(), table.begin() + bytes));
  EXPECT_EQ(value(r.back()), 0u) << "RPC memory access read back on";
  EXPECT_FALSE(card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.lbp_registers().rpcmem; }));
}

TEST(EthBatching, AnRpcTableSliceIsOnePacket) {
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  read_modes(*link);
  const auto before = packets(*link);
  const auto r = link->execute(rpc_slice(64));
  EXPECT_EQ(packets(*link) - before, 1u);
  expect_the_table(card, r, 64);
}

TEST(EthBatching, AnRpcTableSliceStaysRightOnASlowSslbp) {
  ethsim::ServerOptions options;
  options.sslbp.processing = std::chrono::microseconds(400);
  test::RunningBoard card(options);
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  read_modes(*link);
  const auto r = link->execute(rpc_slice(64));
  EXPECT_GT(link->stats().replays, 0u);
  expect_the_table(card, r, 64);
}

TEST(EthBatching, AWaitTooShortForTheSerialTimeIsCaught) {
  // The estimate leaves out the remote's turnaround and SSLBP's processing: too short for
  // the virtual card's timing, which the checks must catch.
  test::RunningBoard card;
  auto options = programs_timing::passthrough();
  options.turnaround_characters = 0;
  options.overhead = 0us;
  const auto link = SslbpPassthroughLink::open(card.target(0), options);
  const std::vector<lbp::Command> batch{lbp::read(kSwRevision, DataSize::Two),
                                        lbp::read(kUnitNumber, DataSize::Four),
                                        lbp::read(kMaxCurrent, DataSize::Two)};
  const auto r = link->execute(batch);
  EXPECT_EQ(value(r[0]), 0xE120u);
  EXPECT_EQ(value(r[1]), 0x00012345u);
  EXPECT_EQ(value(r[2]), 1000u);
  EXPECT_GT(link->stats().late_doits, 0u);
}

TEST(EthBatching, ASlowEepromIsWaitedForNotWrittenTwice) {
  ethsim::ServerOptions options;
  options.amplifier.eeprom_word_time = std::chrono::milliseconds(12);  // beyond the 5 ms estimate
  options.sslbp.remote_timeout = std::chrono::milliseconds(40);
  test::RunningBoard card(options);
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const auto writes = card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.stats().eeprom_writes; });
  const auto batch = nv_write(kNvBrakeOnV, 19000);
  const auto r = link->execute(batch);
  EXPECT_EQ(value(r[1]), 1u);
  EXPECT_EQ(value(r[3]), 19000u);
  EXPECT_EQ(value(r[4]), 1u);
  EXPECT_GT(link->stats().late_doits, 0u) << "the cell outlived its WaituS";
  EXPECT_EQ(card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.stats().eeprom_writes; }),
            writes + 1);
  EXPECT_EQ(value(link->execute_one(lbp::local_read(L::kGetNvAccess))), 0u) << "NV mode left";
}

TEST(EthBatching, CardsWithoutTheTimerSpacePollEveryDoit) {
  ethsim::ServerOptions options;
  options.config = ethsim::BoardConfig::preset(ethsim::BoardKind::I7i96s);
  options.config->lbp16_version = 2;  // older firmware: no space 4, no WaituS
  test::RunningBoard card(options);
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  const auto batch = dump_like();
  const auto r = link->execute(batch);
  EXPECT_EQ(value(r[2 + 24 + 1 + 10]), 34000u);
  EXPECT_GE(link->stats().round_trips, batch.size()) << "one DOIT per packet";
  EXPECT_EQ(ignored_doits(card), 0u);
}

TEST(EthBatching, ALostReplyIsResentWhenTheBatchMayRunTwice) {
  test::RunningBoard card;
  auto bus = std::make_unique<LosingTransport>(card.address(), 0);
  auto* losing = bus.get();
  SslbpPassthroughLink link(std::move(bus), card.target(0), resending());
  losing->lose(1);
  const std::vector<lbp::Command> batch{lbp::write(kBrakeOnV, DataSize::Two, 30003),
                                        lbp::read(kBrakeOnV, DataSize::Two),
                                        lbp::read(kSwRevision, DataSize::Two)};
  const auto r = link.execute(batch);
  EXPECT_EQ(value(r[1]), 30003u);
  EXPECT_EQ(value(r[2]), 0xE120u);
  EXPECT_GE(link.stats().replays, 1u);
}

TEST(EthBatching, ALostReplyOfAResetIsNeverResent) {
  test::RunningBoard card;
  auto bus = std::make_unique<LosingTransport>(card.address(), 0);
  auto* losing = bus.get();
  SslbpPassthroughLink link(std::move(bus), card.target(0), resending());
  const auto resets = card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.stats().resets; });
  losing->lose(1);
  // Either the probe finds the reset's DOIT still running (and reports how it ended) or
  // it cannot tell whether the reset ran: never is it sent a second time.
  try {
    link.execute_one(lbp::reset_processor());
  } catch (const link::LinkError& e) {
    EXPECT_EQ(e.completed(), 0u) << e.what();
  }
  const auto reset_count = [&] {
    return card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.stats().resets; });
  };
  // The DOIT runs on the server's thread. Every packet the link sent was answered before
  // execute_one() returned (the loss is the test's, after the reply), so a second reset, had
  // one been sent, was started by then: once the SSLBP is idle again, every DOIT it was
  // given has run, and the count is final.
  const auto settled = [&] {
    return card.server().with_card([](ethsim::VirtualBoard& c) { return !c.sslbp(0).busy(); }) &&
           reset_count() > resets;
  };
  ASSERT_TRUE(test::eventually(settled, 20s)) << "the reset never ran";
  EXPECT_EQ(reset_count(), resets + 1);
}

TEST(EthBatching, OneDoitServesEveryChannelOfThePort) {
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{0, 0}, {0, 1}, {0, 2}, {0, 3}};
  test::RunningBoard card(options);
  const auto port = PassthroughPort::open(card.address(), 0, 0x0F, programs_timing::passthrough());
  const auto batch = dump_like();
  std::vector<PassthroughPort::Batch> batches;
  for (unsigned ch = 0; ch < 4; ++ch) batches.push_back({.channel = ch, .commands = batch});
  const auto trips = port->transport_stats().packets_sent;
  const auto outcomes = port->execute(batches);
  for (unsigned ch = 0; ch < 4; ++ch) {
    ASSERT_FALSE(outcomes[ch].error) << ch;
    EXPECT_EQ(value(outcomes[ch].replies[1]), 0x00012345u + ch) << "each channel's own unit number";
    EXPECT_EQ(value(outcomes[ch].replies[2 + 24 + 1 + 10]), 34000u) << ch;
  }
  // One DOIT per command for the four channels at once, not four times as many, plus two
  // where a packet boundary falls inside NV access mode: the mode is cleared at the end of
  // one packet and set again at the start of the next (bracket_modes).
  const auto packets = port->transport_stats().packets_sent - trips;
  EXPECT_LE(packets, 3u);
  EXPECT_GE(port->stats().doits, batch.size());
  EXPECT_LE(port->stats().doits, batch.size() + 2 * (packets - 1)) << "not four times as many";
}

TEST(EthBatching, ChannelsOfDifferentLengthsAndAFailingChannel) {
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{0, 0}, {0, 1}, {0, 5}};
  test::RunningBoard card(options);
  const auto port = PassthroughPort::open(card.address(), 0, 0x23, programs_timing::passthrough());
  card.with_amplifier(0, 1, [](sim::Virtual8i20& amp) {
    sim::Injection mute;
    mute.answer_limit = 1;  // answers one more command, then goes silent
    amp.set_injection(mute);
  });
  const std::vector<lbp::Command> shorter{lbp::read(kUnitNumber, DataSize::Four)};
  const auto longer = dump_like();
  const std::vector<PassthroughPort::Batch> batches{{.channel = 0, .commands = shorter},
                                                    {.channel = 1, .commands = longer},
                                                    {.channel = 5, .commands = longer}};
  const auto outcomes = port->execute(batches);
  ASSERT_FALSE(outcomes[0].error);
  EXPECT_EQ(value(outcomes[0].replies[0]), 0x00012345u);
  ASSERT_FALSE(outcomes[2].error);
  EXPECT_EQ(value(outcomes[2].replies[1]), 0x00012347u);
  ASSERT_TRUE(outcomes[1].error);
  try {
    std::rethrow_exception(outcomes[1].error);
  } catch (const link::TimeoutError& e) {
    EXPECT_EQ(e.completed(), 1u) << e.what();
    EXPECT_NE(std::string(e.what()).find("ch 1"), std::string::npos) << e.what();
  }
}

TEST(EthBatching, LinksOfSeveralThreadsShareTheirDoits) {
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{1, 2}, {1, 3}, {1, 4}};
  test::RunningBoard card(options);
  const auto port = PassthroughPort::open(card.address(), 1, 0x1C, programs_timing::passthrough());
  std::vector<std::unique_ptr<link::Link>> links;
  for (unsigned ch = 2; ch <= 4; ++ch) links.push_back(port->link(ch));
  EXPECT_EQ(links[1]->describe(), "eth " + card.address().describe() + " port 1 ch 3");
  EXPECT_EQ(links[0]->max_data_bytes(), 4u);
  std::vector<std::uint64_t> units(3);
  std::vector<std::thread> threads;
  const auto batch = dump_like();
  for (std::size_t i = 0; i < links.size(); ++i)
    threads.emplace_back([&, i] {
      try {
        units[i] = value(links[i]->execute(batch)[1]);
      } catch (const std::exception& e) {
        ADD_FAILURE() << e.what();
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(units, (std::vector<std::uint64_t>{0x00012345u, 0x00012346u, 0x00012347u}));
  EXPECT_LT(port->stats().doits, 3 * batch.size())
      << "combined: fewer DOITs than one per command per channel";
  EXPECT_THROW(port->link(0), UsageError) << "channel 0 is not set up";
}

TEST(EthReadOnly, ALatchedFaultSurvivesAnyNumberOfPassthroughReads) {
  // Reading is read-only: a setup start does no device specific setup (8I20 manual, SETUP
  // START), so FAULT stays latched however often faults are looked at this way.
  test::RunningBoard card;
  const auto fault = [&] {
    return card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { return amp.amplifier().value("FAULT"); });
  };
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { amp.world().settings().enable = false; });
  // The server's thread advances the 8I20's time: wait for the fault to latch, not a time.
  ASSERT_TRUE(test::eventually([&] { return (fault() & 0x0002) != 0; })) << "NOENABLEFAULT never latched";
  card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { amp.world().settings().enable = true; });
  const std::uint64_t latched = fault();
  ASSERT_TRUE(latched & 0x0002) << "NOENABLEFAULT latched, cause gone";
  const std::vector<lbp::Command> look{lbp::read(kFault, DataSize::Two), lbp::read(kStatus, DataSize::Two)};
  for (int i = 0; i < 5; ++i) {
    const auto link =
        SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());  // each look opens anew
    for (int j = 0; j < 3; ++j) EXPECT_EQ(value(link->execute(look)[0]) & latched, latched) << i << "/" << j;
  }
  EXPECT_EQ(card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { return amp.amplifier().value("FAULT"); }) &
                latched,
            latched);
  // A normal start is not a look: it clears them (what kNormalStartEffect tells the user).
  {
    const auto session = NormalModeSession::open(card.target(0), programs_timing::normal_mode());
    session->wait_for_sample(500ms);
  }
  EXPECT_EQ(card.with_amplifier(0, 0, [](sim::Virtual8i20& amp) { return amp.amplifier().value("FAULT"); }) &
                latched,
            0u);
  EXPECT_NE(std::string(kNormalStartEffect).find("clears"), std::string::npos);
}

TEST(EthReadOnly, LinuxCncsMaxcurrentReadFindsMaxcurrent) {
  // LinuxCNC reads 2 bytes at RAM 0x08E8 in setup mode to scale its current pin
  // (docs/facts.md s2): the virtual card answers MAXCURRENT there, not 0.
  test::RunningBoard card;
  const auto link = SslbpPassthroughLink::open(card.target(0), programs_timing::passthrough());
  EXPECT_EQ(value(link->execute_one(lbp::read(kMaxCurrent, DataSize::Two))), 1000u);
}

TEST(EthBatching, TwoPortsOfOneCardAtOnceShareOneTransport) {
  // A fleet over both ports of a 7I92T: over one card transport each port counts the
  // other's packets as ours; over two UDP clients they would be another host's.
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{0, 0}, {1, 0}};
  test::RunningBoard card(options);
  const auto bus =
      PassthroughPort::board_transport(card.address(), programs_timing::udp(), programs_timing::fence());
  const auto port0 = PassthroughPort::open(bus, 0, 0x01, programs_timing::passthrough());
  const auto port1 = PassthroughPort::open(bus, 1, 0x01, programs_timing::passthrough());
  const auto batch = dump_like();
  std::vector<std::uint64_t> units(2);
  std::vector<std::string> errors(2);
  std::vector<std::thread> threads;
  for (unsigned p = 0; p < 2; ++p)
    threads.emplace_back([&, p] {
      try {
        auto link = (p == 0 ? port0 : port1)->link(0);
        for (int i = 0; i < 5; ++i) units[p] = value(link->execute(batch)[1]);
      } catch (const std::exception& e) {
        errors[p] = e.what();
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(errors, (std::vector<std::string>{"", ""}));
  EXPECT_EQ(units, (std::vector<std::uint64_t>{0x00012345u, 0x00012346u}));
}
