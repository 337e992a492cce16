// SPDX-License-Identifier: GPL-2.0-or-later
// PipelinedLink against a scripted in-process 8I20 (scripted_stream.hpp): setup-mode
// pipelining (manual "FRAMING"), the window and barrier cautions (docs/facts.md section 7),
// reply splitting, CRC and timeout errors, and resynchronisation.
#include "link/pipelined_link.hpp"

#include <gtest/gtest.h>

#include <numeric>

#include "lbp/command.hpp"
#include "scripted_stream.hpp"

using namespace i20;
using namespace i20::link;
using namespace std::chrono_literals;
using fake::Script;
using fake::ScriptedStream;
using lbp::Bytes;
using lbp::Command;
using lbp::DataSize;

namespace {

// The link's figures, named here (the programs' are set in ops/core/timing.hpp): each batch sent
// once, a reply awaited `base` plus its wire time.
PipelinedLinkOptions quick(std::chrono::milliseconds base = 20ms) {
  return {.base_timeout = base, .retries = 0u, .max_drain = std::chrono::milliseconds(500)};
}

struct Rig {
  std::shared_ptr<Script> script = std::make_shared<Script>();
  std::unique_ptr<PipelinedLink> link;

  explicit Rig(PipelinedLinkOptions options = quick(50ms)) {
    link = std::make_unique<PipelinedLink>(std::make_unique<ScriptedStream>(script), options);
  }
  std::vector<Bytes> run(const std::vector<Command>& batch) { return link->execute(batch); }
};

// `count` 2-byte reads at 0x100, 0x102, ...: 4 wire bytes each.
std::vector<Command> reads(std::size_t count, std::uint16_t base = 0x100) {
  std::vector<Command> batch;
  for (std::size_t i = 0; i < count; ++i)
    batch.push_back(lbp::read(static_cast<std::uint16_t>(base + 2 * i), DataSize::Two));
  return batch;
}

void fill(Script& s, std::uint16_t base, std::size_t bytes) {
  for (std::size_t i = 0; i < bytes; ++i)
    s.card.at(static_cast<std::uint16_t>(base + i)) = static_cast<lbp::Byte>(i * 7 + 1);
}

Bytes expected_read(Script& s, std::uint16_t address, std::size_t n) {
  Bytes out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(s.card.at(static_cast<std::uint16_t>(address + i)));
  return out;
}

Bytes concat(const std::vector<Bytes>& parts) {
  Bytes out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

// An EEPROM-style write the scripted device treats as a barrier (address >= 0x8000).
Command nv_write(std::uint16_t address, std::uint16_t value) {
  auto c = lbp::write(address, DataSize::Two, value);
  c.barrier = true;
  return c;
}

template <typename E, typename F>
E expect_throw(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "unexpected exception: " << e.what();
    throw;
  }
  ADD_FAILURE() << "no exception";
  throw std::logic_error("no exception");
}

}  // namespace

TEST(PipelinedLink, BatchWithinWindowGoesOutInOneWrite) {
  Rig rig;
  fill(*rig.script, 0x100, 20);
  const auto batch = reads(10);  // 40 wire bytes < 64
  const auto replies = rig.run(batch);
  ASSERT_EQ(rig.script->writes.size(), 1u);
  EXPECT_EQ(rig.script->writes[0], lbp::frame_all(batch));
  ASSERT_EQ(replies.size(), 10u);
  for (std::size_t i = 0; i < 10; ++i)
    EXPECT_EQ(replies[i], expected_read(*rig.script, static_cast<std::uint16_t>(0x100 + 2 * i), 2));
  EXPECT_EQ(rig.script->bad_command_crcs, 0u);
}

TEST(PipelinedLink, WindowBoundsUnansweredCommandBytes) {
  for (std::size_t window : {64u, 20u, 8u}) {
    PipelinedLinkOptions options = quick(50ms);
    options.window_bytes = window;
    Rig rig(options);
    fill(*rig.script, 0x100, 60);
    const auto batch = reads(30);  // 120 wire bytes
    const auto replies = rig.run(batch);
    EXPECT_GT(rig.script->writes.size(), 1u) << window;
    for (const auto& w : rig.script->writes) EXPECT_LE(w.size(), window) << window;
    EXPECT_LE(rig.script->max_unanswered, window) << window;
    EXPECT_EQ(concat(rig.script->writes), lbp::frame_all(batch)) << "order and content preserved";
    for (std::size_t i = 0; i < 30; ++i)
      EXPECT_EQ(replies[i], expected_read(*rig.script, static_cast<std::uint16_t>(0x100 + 2 * i), 2));
    EXPECT_EQ(rig.link->statistics().max_bytes_in_flight, rig.script->max_unanswered);
  }
}

TEST(PipelinedLink, CommandLargerThanWindowGoesAlone) {
  PipelinedLinkOptions options = quick(50ms);
  options.window_bytes = 3;  // smaller than any data command with an address
  Rig rig(options);
  const std::vector<Command> batch{lbp::write(0x10, DataSize::Eight, 0x1122334455667788),
                                   lbp::read(0x10, DataSize::Eight), lbp::local_read(lbp::local::kGetCookie)};
  const auto replies = rig.run(batch);
  ASSERT_EQ(rig.script->writes.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(rig.script->writes[i], lbp::frame(batch[i]));
  EXPECT_EQ(replies[1], lbp::to_le(0x1122334455667788, 8));
  EXPECT_EQ(replies[2], Bytes{0x5A});
}

TEST(PipelinedLink, NothingIsSentAfterABarrierUntilItsReplyArrived) {
  Rig rig(quick(500ms));
  rig.script->delay[2] = 30ms;  // an EEPROM cell write takes milliseconds
  rig.script->delay[3] = 30ms;
  const std::vector<Command> batch{
      lbp::write(0x10, DataSize::Two, 1), lbp::write(0x12, DataSize::Two, 2),
      nv_write(0x8002, 0x1234),           nv_write(0x8004, 0x5678),
      lbp::read(0x8002, DataSize::Four),  lbp::local_read(lbp::local::kGetCookie)};
  const auto replies = rig.run(batch);
  EXPECT_EQ(rig.script->writes_during_barrier, 0u);
  ASSERT_EQ(rig.script->writes.size(), 3u);
  // Commands before a barrier share its write; the barrier ends it.
  EXPECT_EQ(rig.script->writes[0], lbp::frame_all({batch[0], batch[1], batch[2]}));
  EXPECT_EQ(rig.script->writes[1], lbp::frame(batch[3]));
  EXPECT_EQ(rig.script->writes[2], lbp::frame_all({batch[4], batch[5]}));
  EXPECT_EQ(replies[4], (Bytes{0x34, 0x12, 0x78, 0x56}));
  EXPECT_EQ(replies[5], Bytes{0x5A});
}

TEST(PipelinedLink, ResetProcessorIsABarrier) {
  Rig rig;
  const std::vector<Command> batch{lbp::reset_processor(), lbp::local_read(lbp::local::kGetCookie)};
  rig.run(batch);
  ASSERT_EQ(rig.script->writes.size(), 2u);
  EXPECT_EQ(rig.script->writes_during_barrier, 0u);
}

TEST(PipelinedLink, SplitsRepliesOfMixedSizesArrivingByteByByte) {
  for (std::size_t chunk : {std::size_t{1}, std::size_t{3}, std::numeric_limits<std::size_t>::max()}) {
    Rig rig;
    rig.script->chunk = chunk;
    const std::vector<Command> batch{lbp::write(0x20, DataSize::Eight, 0x0807060504030201),
                                     lbp::read(0x20, DataSize::One),
                                     lbp::read(0x20, DataSize::Two),
                                     lbp::read(0x20, DataSize::Four),
                                     lbp::read(0x20, DataSize::Eight),
                                     lbp::local_write(lbp::local::kSetStatus, 0),
                                     lbp::local_read(lbp::local::kGetCookie)};
    const auto replies = rig.run(batch);
    ASSERT_EQ(replies.size(), batch.size());
    EXPECT_EQ(replies[0], Bytes{});
    EXPECT_EQ(replies[1], (Bytes{1}));
    EXPECT_EQ(replies[2], (Bytes{1, 2}));
    EXPECT_EQ(replies[3], (Bytes{1, 2, 3, 4}));
    EXPECT_EQ(replies[4], (Bytes{1, 2, 3, 4, 5, 6, 7, 8}));
    EXPECT_EQ(replies[5], Bytes{});
    EXPECT_EQ(replies[6], Bytes{0x5A});
  }
}

TEST(PipelinedLink, CrcErrorNamesTheCommandAndCountsCompleted) {
  Rig rig(quick());
  fill(*rig.script, 0x100, 10);
  rig.script->corrupt.insert(2);
  const auto e = expect_throw<CrcError>([&] { rig.run(reads(5)); });
  EXPECT_EQ(e.completed(), 2u);
  const std::string text = e.what();
  EXPECT_NE(text.find("command 3 of 5"), std::string::npos) << text;
  EXPECT_NE(text.find(lbp::to_hex(reads(5)[2].bytes)), std::string::npos) << text;
  EXPECT_NE(text.find("/dev/fake0"), std::string::npos) << text;
  EXPECT_EQ(rig.link->statistics().crc_errors, 1u);
  EXPECT_EQ(rig.link->statistics().resyncs, 1u);
  // The replies to commands 4 and 5 were drained, so the next batch lines up.
  rig.script->corrupt.clear();
  const auto replies = rig.run(reads(2, 0x104));
  EXPECT_EQ(replies[0], expected_read(*rig.script, 0x104, 2));
  EXPECT_EQ(replies[1], expected_read(*rig.script, 0x106, 2));
}

TEST(PipelinedLink, SilentCardTimesOutWithinTheDeadlineAndSaysWhatToCheck) {
  Rig rig(quick());
  rig.script->mute_from = 0;
  const auto start = Clock::now();
  const auto e = expect_throw<TimeoutError>([&] { rig.run(reads(3)); });
  EXPECT_LT(Clock::now() - start, 2s);
  EXPECT_EQ(e.completed(), 0u);
  const std::string text = e.what();
  EXPECT_NE(text.find("/dev/fake0"), std::string::npos) << text;
  EXPECT_NE(text.find("W6"), std::string::npos) << text;
  EXPECT_NE(text.find("J1"), std::string::npos) << text;
  EXPECT_EQ(rig.link->statistics().timeouts, 1u);
}

TEST(PipelinedLink, TimeoutMidBatchCountsTheRepliesThatArrived) {
  Rig rig(quick());
  rig.script->mute_from = 3;
  const auto e = expect_throw<TimeoutError>([&] { rig.run(reads(6)); });
  EXPECT_EQ(e.completed(), 3u);
  const std::string text = e.what();
  EXPECT_NE(text.find("answered 3 of 6"), std::string::npos) << text;
  EXPECT_NE(text.find("window"), std::string::npos) << text;
}

TEST(PipelinedLink, TimeoutGrowsWithTheWireTimeOfBytesInFlight) {
  auto options = quick();
  options.resync_idle = 10ms;  // the automatic one is 1.7 s at 300 baud
  Rig rig(options);
  rig.script->baud = 300;  // one 2-byte read: 4 + 3 wire bytes = 233 ms at 300 baud
  rig.script->delay[0] = 100ms;
  EXPECT_NO_THROW(rig.run(reads(1)));
  rig.script->mute_from = 1;
  const auto e = expect_throw<TimeoutError>([&] { rig.run(reads(1)); });
  EXPECT_NE(std::string(e.what()).find("within 254 ms"), std::string::npos) << e.what();
}

TEST(PipelinedLink, ResyncDrainsALateReplySoTheNextBatchIsClean) {
  auto options = quick();
  options.resync_idle = 150ms;
  Rig rig(options);
  fill(*rig.script, 0x100, 10);
  rig.script->late_tail[1] = {1, 60ms};  // one byte now, the rest after the timeout
  const auto e = expect_throw<TimeoutError>([&] { rig.run(reads(2)); });
  EXPECT_EQ(e.completed(), 1u);
  EXPECT_GE(rig.script->discards, 1u);
  const auto replies = rig.run(reads(1, 0x108));
  EXPECT_EQ(replies[0], expected_read(*rig.script, 0x108, 2));
  EXPECT_EQ(rig.link->statistics().resyncs, 1u);
  EXPECT_EQ(rig.link->statistics().stale_bytes, 2u);  // the late 1 data byte + CRC
}

TEST(PipelinedLink, ResyncStaysQuietLongerThanTheCardsCommandTimeout) {
  Rig rig;
  // 25.5 character times of 10 bits: 2.21 ms at 115200, 26.6 ms at 9600.
  EXPECT_GE(rig.link->resync_idle(), 2214us);
  rig.script->baud = 9600;
  EXPECT_GE(rig.link->resync_idle(), 26563us);
  EXPECT_LT(rig.link->resync_idle(), 100ms);
}

TEST(PipelinedLink, StaleBytesBeforeABatchAreDropped) {
  Rig rig;
  fill(*rig.script, 0x100, 4);
  rig.script->inject(Bytes{0x00, 0x12, 0x34});
  const auto replies = rig.run(reads(2));
  EXPECT_EQ(replies[0], expected_read(*rig.script, 0x100, 2));
  EXPECT_EQ(replies[1], expected_read(*rig.script, 0x102, 2));
  EXPECT_EQ(rig.link->statistics().stale_bytes, 3u);
  EXPECT_EQ(rig.link->statistics().resyncs, 1u);
}

TEST(PipelinedLink, SurplusBytesAfterTheLastReplyAreAFramingError) {
  Rig rig(quick());
  rig.script->extra[0] = Bytes{0x00};  // a write's reply, twice
  const std::vector<Command> batch{lbp::write(0x10, DataSize::One, 5)};
  const auto e = expect_throw<FramingError>([&] { rig.run(batch); });
  EXPECT_EQ(e.completed(), 0u);
  EXPECT_NE(std::string(e.what()).find("/dev/fake0"), std::string::npos);
  rig.script->extra.clear();
  EXPECT_EQ(rig.link->execute_one(lbp::read(0x10, DataSize::One)), Bytes{5});
}

TEST(PipelinedLink, RetriesReadOnlyBatchesWhenAskedAndNeverWrites) {
  auto options = quick();
  options.retries = 2;
  {
    Rig rig(options);
    fill(*rig.script, 0x100, 4);
    rig.script->ignore_next = 2;  // the first attempt's commands vanish
    const auto replies = rig.run(reads(2));
    EXPECT_EQ(replies[1], expected_read(*rig.script, 0x102, 2));
    EXPECT_EQ(rig.link->statistics().retries, 1u);
    EXPECT_EQ(rig.script->commands.size(), 4u);
  }
  {
    Rig rig(options);
    rig.script->ignore_next = 1;
    const std::vector<Command> batch{lbp::write(0x10, DataSize::One, 5)};
    EXPECT_THROW(rig.run(batch), TimeoutError);
    EXPECT_EQ(rig.script->commands.size(), 1u) << "a write must never be resent silently";
    EXPECT_EQ(rig.link->statistics().retries, 0u);
  }
  {
    Rig rig(quick());  // retries default to 0
    rig.script->ignore_next = 2;
    EXPECT_THROW(rig.run(reads(2)), TimeoutError);
    EXPECT_EQ(rig.script->commands.size(), 2u);
  }
}

TEST(PipelinedLink, RetrySafetyFollowsWhatACommandCanChange) {
  using lbp::local_read;
  using lbp::local_write;
  const auto safe = [](std::vector<Command> b) { return PipelinedLink::retry_safe(b); };
  EXPECT_TRUE(safe(reads(3)));
  EXPECT_TRUE(safe({local_read(lbp::local::kGetStatus), lbp::read(0, DataSize::One)}));
  EXPECT_FALSE(safe({lbp::read(0, DataSize::One), lbp::write(0, DataSize::One, 1)}));
  EXPECT_FALSE(safe({local_write(lbp::local::kSetStatus, 0)}));
  EXPECT_FALSE(safe({lbp::rpc(1, {}, 2)}));
  EXPECT_FALSE(safe({lbp::reset_processor()}));
  // Reads at the pointer: safe once the batch set the pointer, or if nothing moves it.
  EXPECT_TRUE(safe({lbp::read(0x10, DataSize::Two, true), lbp::read_at_pointer(DataSize::Two, true)}));
  EXPECT_FALSE(safe({lbp::read_at_pointer(DataSize::Two, true)}));
  EXPECT_TRUE(safe({lbp::read_at_pointer(DataSize::Two, false)}));
}

TEST(PipelinedLink, StatisticsCountTraffic) {
  Rig rig;
  const auto batch = reads(20);
  rig.run(batch);
  rig.run(reads(1));
  const auto& s = rig.link->statistics();
  EXPECT_EQ(s.exchanges, 2u);
  EXPECT_EQ(s.commands, 21u);
  EXPECT_EQ(s.bytes_sent, 21u * 4);
  EXPECT_EQ(s.bytes_received, 21u * 3);
  EXPECT_EQ(s.bursts, rig.script->writes.size());
  EXPECT_EQ(s.resyncs, 0u);
  rig.link->reset_statistics();
  EXPECT_EQ(rig.link->statistics().commands, 0u);
}

TEST(PipelinedLink, EmptyBatchTouchesNothing) {
  Rig rig;
  EXPECT_TRUE(rig.run({}).empty());
  EXPECT_TRUE(rig.script->writes.empty());
  EXPECT_EQ(rig.link->describe(), "/dev/fake0");
}

TEST(PipelinedLink, RejectsUnusableOptionsAndCommands) {
  PipelinedLinkOptions options = quick(50ms);
  options.window_bytes = 0;
  EXPECT_THROW(Rig{options}, UsageError);
  Rig rig;
  EXPECT_THROW(rig.run({Command{}}), UsageError);
  EXPECT_THROW(PipelinedLink(nullptr, quick()), UsageError);
}
