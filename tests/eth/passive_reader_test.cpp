// SPDX-License-Identifier: GPL-2.0-or-later
// The passive reader and monitor against the virtual card with its running host: the
// process data of every channel as the 8I20 manual lays it out, reads only, the rate bound.
#include "eth/passive_reader.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <functional>
#include <mutex>

#include "ethsim/board_control.hpp"
#include "fixtures.hpp"
#include "ops/watch/passive_monitor.hpp"
#include "ops/watch/passive_watch.hpp"
#include "programs_timing.hpp"

using namespace i20;
using namespace i20::eth;
using namespace std::chrono_literals;

namespace {

unsigned long host_doits(test::RunningBoard& card) {
  const auto status = card.server().host_status();
  if (!status) return 0;
  const auto end = status->find(" DOITs");
  if (end == std::string::npos) return 0;
  const auto begin = status->rfind(' ', end - 1);
  return std::stoul(status->substr(begin + 1, end - begin - 1));
}

// A 7I92T with 8I20s on port 0 channels 0 and 1, run by the stand-in.
ethsim::ServerOptions machine() {
  ethsim::ServerOptions o;
  o.card = ethsim::BoardKind::I7i92t;
  o.amplifiers = {{0, 0}, {0, 1}};
  o.host = ethsim::HostOptions{};
  return o;
}

// What went on the wire: every request's commands and when it went.
struct Log {
  std::mutex mutex;
  std::vector<std::chrono::steady_clock::time_point> sent;
  std::size_t writes = 0;
};

class LoggingTransport final : public Lbp16Transport {
 public:
  LoggingTransport(std::unique_ptr<Lbp16Transport> inner, Log& log) : inner_(std::move(inner)), log_(log) {}
  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands, Resend resend) override {
    {
      std::lock_guard lock(log_.mutex);
      log_.sent.push_back(std::chrono::steady_clock::now());
      for (const auto& c : commands) log_.writes += c.word.write ? 1 : 0;
    }
    return inner_->transact(commands, resend);
  }
  std::string describe() const override { return inner_->describe(); }
  TransportStats stats() const override { return inner_->stats(); }

 private:
  std::unique_ptr<Lbp16Transport> inner_;
  Log& log_;
};

std::unique_ptr<Lbp16Transport> logged(const HostPort& host_port, Log& log) {
  auto udp = programs_timing::udp();
  udp.sequence_tags = false;
  udp.retries = 0;
  udp.timeout = 500ms;
  return std::make_unique<LoggingTransport>(std::make_unique<UdpClient>(host_port.ip, host_port.port, udp),
                                            log);
}

// A card that stops answering on demand: the next `unanswered` requests time out.
class SilenceableTransport final : public Lbp16Transport {
 public:
  SilenceableTransport(std::unique_ptr<Lbp16Transport> inner, std::atomic<int>& unanswered)
      : inner_(std::move(inner)), unanswered_(unanswered) {}
  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands, Resend resend) override {
    if (unanswered_ > 0) {
      --unanswered_;
      throw link::TimeoutError("no reply (test)");
    }
    return inner_->transact(commands, resend);
  }
  std::string describe() const override { return inner_->describe(); }
  TransportStats stats() const override { return inner_->stats(); }

 private:
  std::unique_ptr<Lbp16Transport> inner_;
  std::atomic<int>& unanswered_;
};

// What `watch --passive` would have shown; `on_sample` acts after each sample.
struct RecordingSink final : ops::PassiveWatchSink {
  std::vector<ops::PassiveSample> samples;
  std::vector<ops::PassiveLinkEvent> events;
  std::function<void()> on_sample;
  void sample(const ops::PassiveSample& s) override {
    samples.push_back(s);
    if (on_sample) on_sample();
  }
  void link(const ops::PassiveLinkEvent& e) override { events.push_back(e); }
};

const ProcessData* channel(const PassiveSnapshot& s, unsigned port, unsigned ch) {
  for (const auto& d : s.channels)
    if (d.port == port && d.channel == ch) return &d;
  return nullptr;
}

}  // namespace

TEST(PassiveReader, ChannelsComeFromThePinTable) {
  test::RunningBoard card(machine());
  PassiveReader reader(card.address(), programs_timing::passive());
  ASSERT_EQ(reader.ports().size(), 2u);
  EXPECT_EQ(reader.channels(0), 8u);  // the 7I92T preset wires 8 channels per port
  EXPECT_EQ(reader.channels(1), 8u);
}

TEST(PassiveReader, ReadsTheManualsProcessDataOfEveryChannelWithoutWriting) {
  test::RunningBoard card(machine());
  ASSERT_TRUE(test::eventually([&] { return host_doits(card) >= 50; }, 30s)) << *card.server().host_status();
  ethsim::apply_board_control(card.server(), "ch 1 busv 48");
  ethsim::apply_board_control(card.server(), "ch 1 temp 61");
  ethsim::apply_board_control(card.server(), "ch 0 fault overcurrent on");
  Log log;
  PassiveReader reader(logged(card.address(), log), programs_timing::passive());
  PassiveSnapshot s;
  ASSERT_TRUE(test::eventually(
      [&] {
        s = reader.read();
        const auto* ch1 = channel(s, 0, 1);
        const auto* ch0 = channel(s, 0, 0);
        return ch0 && ch1 && ch1->busv_v() > 47.99 && ch1->temperature_c() == 61 && (ch0->fault() & 0x0010);
      },
      10s));
  const auto* ch0 = channel(s, 0, 0);
  const auto* ch1 = channel(s, 0, 1);
  EXPECT_TRUE(ch0->live());
  EXPECT_TRUE(ch1->live());
  EXPECT_EQ(ch1->interface0 >> 16, 4800u);  // 10 mV units in the high word
  EXPECT_NEAR(ch0->busv_v(), 320.0, 0.01);
  EXPECT_EQ(ch1->fault() & 0x0010, 0);
  // The other port's channels and port 0's unused ones hold nothing.
  EXPECT_FALSE(channel(s, 0, 2)->is_8i20());
  EXPECT_FALSE(channel(s, 1, 0)->is_8i20());
  std::lock_guard lock(log.mutex);
  EXPECT_EQ(log.writes, 0u) << "a passive reader writes nothing, not even a sequence tag";
  const auto host = *card.server().host_status();
  EXPECT_NE(host.find("(0 failed)"), std::string::npos) << host;
}

TEST(PassiveReader, NeverSendsMoreThanTwentyRequestsInAnySecond) {
  test::RunningBoard card(machine());
  Log log;
  PassiveReader reader(logged(card.address(), log), programs_timing::passive());
  for (int i = 0; i < 30; ++i) reader.read();  // as fast as the reader lets us
  std::lock_guard lock(log.mutex);
  ASSERT_EQ(log.sent.size(), 31u);  // the survey and 30 snapshots: one request each, batched
  for (std::size_t i = 0; i + ops::timing::kPassiveMaxRequestsPerSecond < log.sent.size(); ++i)
    EXPECT_GE(log.sent[i + ops::timing::kPassiveMaxRequestsPerSecond] - log.sent[i], 1s)
        << "window at request " << i;
  EXPECT_EQ(reader.requests_sent(), 31u);
  EXPECT_EQ(log.writes, 0u);
}

TEST(PassiveMonitor, ReportsTimestampedChangesDecodedByTheFaultTable) {
  test::RunningBoard card(machine());
  ASSERT_TRUE(test::eventually([&] { return host_doits(card) >= 50; }, 30s)) << *card.server().host_status();
  ops::PassiveMonitor monitor(card.address(), {.read = programs_timing::passive()});
  auto first = monitor.sample();
  ASSERT_EQ(first.amplifiers.size(), 2u);
  const auto joined = std::count_if(first.changes.begin(), first.changes.end(),
                                    [](const auto& c) { return c.kind == ops::PassiveChange::Kind::Joined; });
  EXPECT_EQ(joined, 2);
  const auto before = std::chrono::system_clock::now();
  ethsim::apply_board_control(card.server(), "ch 1 fault overcurrent on");
  std::vector<ops::PassiveChange> seen;
  ASSERT_TRUE(test::eventually(
      [&] {
        for (const auto& c : monitor.sample().changes) seen.push_back(c);
        return std::any_of(seen.begin(), seen.end(), [](const auto& c) {
          return c.kind == ops::PassiveChange::Kind::FaultSet && c.name == "CURRENTFAULT";
        });
      },
      10s));
  const auto it =
      std::find_if(seen.begin(), seen.end(), [](const auto& c) { return c.name == "CURRENTFAULT"; });
  EXPECT_EQ(it->channel, 1u);
  EXPECT_EQ(it->bit, 4u);
  EXPECT_GE(it->when, before);
  EXPECT_NE(it->text.find("port 0 ch 1: FAULT set: CURRENTFAULT (bit 4)"), std::string::npos) << it->text;
  EXPECT_NE(card.server().host_status()->find("(0 failed)"), std::string::npos);
}

TEST(PassiveMonitor, SaysWhenTheHostGoesQuiet) {
  test::RunningBoard card(machine());
  ASSERT_TRUE(test::eventually([&] { return host_doits(card) >= 20; }, 30s));
  ops::PassiveMonitor monitor(card.address(), {.read = programs_timing::passive()});
  monitor.sample();
  EXPECT_EQ(monitor.sample().host_active(), true);
  card.server().stop_host();
  std::vector<ops::PassiveChange> seen;
  ASSERT_TRUE(test::eventually(
      [&] {
        for (const auto& c : monitor.sample().changes) seen.push_back(c);
        return std::any_of(seen.begin(), seen.end(),
                           [](const auto& c) { return c.kind == ops::PassiveChange::Kind::HostQuiet; });
      },
      10s));
}

TEST(PassiveWatch, SaysOnceWhenTheCardStopsAnsweringAndAgainWhenItIsBack) {
  test::RunningBoard card(machine());
  ASSERT_TRUE(test::eventually([&] { return host_doits(card) >= 20; }, 30s));
  Log log;
  std::atomic<int> unanswered{0};
  ops::PassiveMonitor monitor(card.address(),
                              std::make_unique<SilenceableTransport>(logged(card.address(), log), unanswered),
                              {.read = programs_timing::passive()});
  RecordingSink sink;
  sink.on_sample = [&] {
    if (sink.samples.size() == 1) unanswered = 3;  // three samples in a row go unanswered
  };
  const auto summary = ops::run_passive_monitor(monitor, {.interval = 50ms, .count = 3}, sink);
  EXPECT_EQ(summary.outcome, ops::Outcome::Done);
  EXPECT_EQ(summary.samples, 3u);
  EXPECT_EQ(sink.samples.size(), 3u);
  EXPECT_EQ(summary.missed, 3u);
  ASSERT_EQ(sink.events.size(), 2u) << "one line for the whole silence, one when it ends";
  EXPECT_EQ(sink.events[0].kind, ops::PassiveLinkEvent::Kind::Lost);
  EXPECT_NE(sink.events[0].text.find("no reply from the card"), std::string::npos) << sink.events[0].text;
  EXPECT_EQ(sink.events[1].kind, ops::PassiveLinkEvent::Kind::Reconnected);
  EXPECT_EQ(sink.events[1].when, sink.samples[1].when) << "back with the sample that answered";
  EXPECT_EQ(log.writes, 0u) << "a passive watch never writes";
}

TEST(PassiveWatch, AViewThatFailsEndsTheWatch) {
  test::RunningBoard card(machine());
  ASSERT_TRUE(test::eventually([&] { return host_doits(card) >= 20; }, 30s));
  ops::PassiveMonitor monitor(card.address(), {.read = programs_timing::passive()});
  struct ReaderGone {};
  RecordingSink sink;
  sink.on_sample = [&] {
    if (sink.samples.size() == 2) throw ReaderGone{};  // stdout closed: app::require_stdout() throws
  };
  EXPECT_THROW(ops::run_passive_monitor(monitor, {.interval = 50ms}, sink), ReaderGone)
      << "no --count, no --duration: only the view's failure ends it";
  EXPECT_EQ(sink.samples.size(), 2u);
}
