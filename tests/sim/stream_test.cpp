// SPDX-License-Identifier: GPL-2.0-or-later
// SimStream (the simulator as a link::ByteStream) and make_sim_link (PipelinedLink on
// top): real time, so only lower bounds on durations are asserted.
#include "bench.hpp"
#include "eventually.hpp"
#include "lbp/command.hpp"
#include "sim/error.hpp"
#include "sim/sim_stream.hpp"

namespace i20::sim::test {
namespace {

lbp::Bytes read_n(link::ByteStream& s, std::size_t n, std::chrono::milliseconds budget = 2000ms) {
  lbp::Bytes out(n);
  std::size_t got = 0;
  const auto deadline = link::Clock::now() + budget;
  while (got < n) {
    const auto k = s.read_some(std::span(out).subspan(got), deadline);
    if (k == 0) break;
    got += k;
  }
  out.resize(got);
  return out;
}

TEST(SimStream, WriteThenReadTheReply) {
  auto s = make_sim_stream();
  EXPECT_EQ(s->baud(), 115200u);
  EXPECT_EQ(s->name(), "simulator");
  s->write(framed("DF"));
  EXPECT_EQ(read_n(*s, 2), reply("5A"));
}

TEST(SimStream, ReadSomeHonoursItsDeadline) {
  auto s = make_sim_stream();
  lbp::Bytes buf(4);
  const auto start = link::Clock::now();
  EXPECT_EQ(s->read_some(buf, start + 20ms), 0u);
  EXPECT_GE(link::Clock::now() - start, 20ms);
}

TEST(SimStream, DiscardInputDropsUnreadReplies) {
  auto s = make_sim_stream();
  s->write(framed("DF"));
  // No wait: the simulator runs on the caller's clock. With no wire time and no turnaround the
  // reply is queued by write() itself, and discard_input() brings the card up to now first.
  s->discard_input();
  lbp::Bytes buf(4);
  EXPECT_EQ(s->read_some(buf, link::Clock::now() + 10ms), 0u);
  s->write(framed("DA"));
  EXPECT_EQ(read_n(*s, 2), reply("03"));
}

TEST(SimStream, EepromWriteTakesRealTime) {
  SimOptions o;
  o.device.eeprom_word_time = 20ms;
  SimStream s(o);
  s.write(framed("EC 01"));
  EXPECT_EQ(read_n(s, 1), lbp::Bytes{0x00});
  const auto start = link::Clock::now();
  s.write(framed("65 02 00 D0 07"));
  EXPECT_EQ(read_n(s, 1), lbp::Bytes{0x00});
  EXPECT_GE(link::Clock::now() - start, 20ms);
}

TEST(SimStream, WireTimeEmulationPacesBytes) {
  SimOptions o;
  o.wire.emulate_wire_time = true;
  o.wire.turnaround = 1ms;
  SimStream s(o);
  lbp::Bytes batch;
  for (int i = 0; i < 50; ++i) batch = cat({batch, framed("DF")});
  const auto start = link::Clock::now();
  s.write(batch);
  EXPECT_EQ(read_n(s, 100).size(), 100u);
  // Full duplex: replies overlap the commands still arriving, so the floor is the 100
  // command bytes at 86.8 us each (8.7 ms) plus the turnaround before the last reply.
  EXPECT_GE(link::Clock::now() - start, 9500us);
}

TEST(SimStream, WorldChangesThroughTheStream) {
  SimStream s;
  EXPECT_EQ(s.control("busv 48"), "ok");
  s.with_card([](Virtual8i20& card) { card.world().settings().temperature_c = 50; });
  s.write(framed("81"));
  EXPECT_EQ(read_n(s, 5), reply("C0 12 88 13"));  // 4800, 5000
  EXPECT_THROW(s.control("busv"), ControlError);
}

// The link's figures, named here (the programs' are set in ops/core/timing.hpp).
constexpr link::PipelinedLinkOptions kLink{
    .base_timeout = 50ms, .retries = 0u, .max_drain = std::chrono::milliseconds(500)};

TEST(SimLink, PipelinedLinkTalksToTheSimulator) {
  auto link = make_sim_link({}, kLink);
  const std::vector<lbp::Command> batch{lbp::local_read(lbp::local::kGetCookie),
                                        lbp::read(2164, lbp::DataSize::Two),
                                        lbp::read(2344, lbp::DataSize::Four), lbp::local_read(0xD1)};
  const auto replies = link->execute(batch);
  ASSERT_EQ(replies.size(), 4u);
  EXPECT_EQ(replies[0], lbp::Bytes{0x5A});
  EXPECT_EQ(replies[1], lbp::from_hex("20 E1"));
  EXPECT_EQ(replies[2], lbp::from_hex("45 23 01 00"));
  EXPECT_EQ(replies[3], lbp::Bytes{'I'});
  EXPECT_EQ(link->describe(), "simulator");
}

TEST(SimLink, NvWriteAndResetThroughTheLink) {
  auto link = make_sim_link({}, kLink);
  auto nv_write = lbp::write(2, lbp::DataSize::Two, 2200);
  nv_write.barrier = true;
  const std::vector<lbp::Command> batch{lbp::set_nv_access(lbp::local::NvAccess::Eeprom), nv_write,
                                        lbp::set_nv_access(lbp::local::NvAccess::Ram),
                                        lbp::reset_processor()};
  EXPECT_EQ(link->execute(batch).size(), 4u);
  // The card reboots, deaf for its reset time: until it answers again (each unanswered ask
  // times out), however long a loaded machine takes to get there.
  ASSERT_TRUE(i20::test::eventually([&] {
    try {
      return link->execute_one(lbp::local_read(lbp::local::kGetCookie)) == lbp::Bytes{0x5A};
    } catch (const link::LinkError&) {
      return false;
    }
  })) << "the card did not come back from its reset";
  const auto maxcurrent =
      link->execute_one(lbp::read(RegisterMap::builtin().at("MAXCURRENT").address, lbp::DataSize::Two));
  EXPECT_EQ(lbp::read_le(maxcurrent), 2200u);
}

TEST(SimLink, DroppedRepliesSurfaceAsTimeouts) {
  SimOptions o;
  o.device.injection.drop_rate = 1.0;
  auto link =
      make_sim_link(o, {.base_timeout = 30ms, .retries = 0u, .max_drain = std::chrono::milliseconds(500)});
  EXPECT_THROW(link->execute_one(lbp::local_read(lbp::local::kGetCookie)), link::TimeoutError);
}

TEST(SimLink, CorruptRepliesSurfaceAsCrcErrors) {
  SimOptions o;
  o.device.injection.corrupt_rate = 1.0;
  auto link = make_sim_link(o, kLink);
  EXPECT_THROW(link->execute_one(lbp::read(2164, lbp::DataSize::Two)), link::LinkError);
}

}  // namespace
}  // namespace i20::sim::test
