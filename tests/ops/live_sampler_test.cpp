// SPDX-License-Identifier: GPL-2.0-or-later
// The console's live view and `i20 watch` pace their retries of a lost card by one rule
// (ops/watch/live_source.hpp): at the sample interval, never more often than
// timing::kMonitorMinRetry, and with the link dropped after each failed read.
#include <gtest/gtest.h>

#include "eventually.hpp"
#include "ops/core/timing.hpp"
#include "ops/watch/live_source.hpp"

namespace i20::ops {
namespace {

using std::chrono::milliseconds;

class FakeSource : public LiveSource {
 public:
  FaultReadings read() override {
    ++reads;
    if (!reachable) throw Error("no reply from the 8I20");
    FaultReadings r;
    r.fault = 0x0004;
    return r;
  }
  std::string describe() override { return "8I20 on a fake port"; }
  void reconnect() override { ++reconnects; }
  std::string method() const override { return "register reads"; }

  bool reachable = true;
  int reads = 0;
  int reconnects = 0;
};

TEST(LiveSampler, RetriesALostCardAtTheIntervalButNotMoreOftenThanTheFloor) {
  EXPECT_EQ(retry_interval(milliseconds(100)), timing::kMonitorMinRetry);
  EXPECT_EQ(retry_interval(milliseconds(2000)), milliseconds(2000));
}

TEST(LiveSampler, ALostCardIsNotAskedAgainAtEveryTick) {
  FakeSource source;
  LiveSampler sampler(source, milliseconds(10));
  auto s = sampler.next();
  ASSERT_TRUE(s.readings);
  EXPECT_EQ(s.readings->fault, 0x0004);

  source.reachable = false;
  const auto lost = std::chrono::steady_clock::now();
  s = sampler.next();
  EXPECT_FALSE(s.readings);
  EXPECT_EQ(s.error, "no reply from the 8I20");
  EXPECT_EQ(source.reconnects, 1) << "the link is dropped: the port may have gone away";
  const int reads_when_lost = source.reads;

  source.reachable = true;
  s = sampler.next();  // a tick within the retry interval: answered without the card
  EXPECT_FALSE(s.readings);
  EXPECT_EQ(s.error, "no reply from the 8I20");
  EXPECT_EQ(source.reads, reads_when_lost);

  ASSERT_TRUE(test::eventually([&] { return sampler.next().readings.has_value(); }));
  EXPECT_GE(std::chrono::steady_clock::now() - lost, timing::kMonitorMinRetry);
  EXPECT_EQ(source.reads, reads_when_lost + 1) << "one read when the retry was due, none before";
}

TEST(LiveSampler, AMisusedCommandIsNotTakenForALostCard) {
  struct Refusing final : FakeSource {
    FaultReadings read() override { throw UsageError("--channel 9: an SSERIAL channel is 0..7"); }
  } source;
  LiveSampler sampler(source, milliseconds(10));
  EXPECT_THROW(sampler.next(), UsageError);
  EXPECT_EQ(source.reconnects, 0);
}

}  // namespace
}  // namespace i20::ops
