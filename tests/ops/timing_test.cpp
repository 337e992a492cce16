// SPDX-License-Identifier: GPL-2.0-or-later
// ops/core/timing.hpp builds every lower layer's options: the rules those figures must keep,
// against the budget (retry.hpp) and the 8I20's 40 ms watchdog (8I20 manual, "8I20 DEVICE
// SPECIFIC SETUP": SSLBP's normal start sets it to 40 mS).
#include "ops/core/timing.hpp"

#include <gtest/gtest.h>

#include <type_traits>

#include "device/amp.hpp"
#include "device/discover.hpp"
#include "eth/normal_mode.hpp"
#include "eth/passive_reader.hpp"
#include "eth/passthrough_port.hpp"
#include "eth/scan.hpp"
#include "link/pipelined_link.hpp"
#include "link/serial_stream.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/retry.hpp"

namespace i20::ops {
namespace {

using std::chrono::milliseconds;

constexpr milliseconds kWatchdog{40};

LinkSettings with_timeout(unsigned ms, bool take_over = false) {
  LinkSettings s;
  s.timeout_ms = ms;
  s.take_over = take_over;
  return s;
}

TEST(Timing, TheLinksUnderOpsSendEachOfItsExchangesOnce) {
  // ops repeats a lost exchange itself (Amp::with_retries): a link that resent too would
  // multiply the budget.
  RetryPolicy retry;
  retry.attempts = 5;
  EXPECT_EQ(timing::serial_link(LinkSettings{}, retry).retries, 0u);
  EXPECT_EQ(timing::passthrough(LinkSettings{}, retry).lost_packet_resends, 0u);
}

TEST(Timing, TheEthernetLayersOwnExchangesSpendTheBudget) {
  // What ops never sees (opening, SSLBP commands, IDROM reads) gets the same sends in all
  // as an exchange of ops': attempts, the first included.
  RetryPolicy retry;
  retry.attempts = 5;
  const auto p = timing::passthrough(LinkSettings{}, retry);
  EXPECT_EQ(p.udp.retries, 4u);
  EXPECT_EQ(p.sslbp.lost_reply_retries, 4u);
  const auto s = timing::scan(LinkSettings{}, retry);
  EXPECT_EQ(s.udp.retries, 4u);
  EXPECT_EQ(s.sslbp.lost_reply_retries, 4u);
  retry.attempts = 1;
  EXPECT_EQ(timing::passthrough(LinkSettings{}, retry).udp.retries, 0u);
}

TEST(Timing, TheReplyTimeoutIsTheUsersOnEveryPath) {
  const auto settings = with_timeout(120);
  EXPECT_EQ(timing::serial_link(settings, {}).base_timeout, milliseconds(120));
  EXPECT_EQ(timing::passthrough(settings, {}).udp.timeout, milliseconds(120));
  EXPECT_EQ(timing::scan(settings).udp.timeout, milliseconds(120));
  // A reply timeout above the UDP ceiling raises the ceiling instead of being cut.
  const auto slow = timing::passthrough(with_timeout(1500), {});
  EXPECT_EQ(slow.udp.timeout, milliseconds(1500));
  EXPECT_GE(slow.udp.max_timeout, slow.udp.timeout);
  // --passive sends each read once: never shorter than its floor, longer when asked.
  EXPECT_EQ(timing::passive(with_timeout(50)).timeout, timing::kPassiveReadFloor);
  EXPECT_EQ(timing::passive(with_timeout(300)).timeout, milliseconds(300));
  EXPECT_EQ(timing::passive(with_timeout(1500)).max_timeout, milliseconds(1500));
}

TEST(Timing, ARunningHostShowsWithinOneWatchAndAStartedAmpStaysFed) {
  // A host that keeps an 8I20 running DOITs within every 40 ms, so a watch longer than
  // that always sees it.
  EXPECT_GT(timing::running_host(LinkSettings{}).window, kWatchdog);
  // Normal mode: one lost cycle still leaves the watchdog fed.
  const auto watch = timing::normal_mode(LinkSettings{});
  EXPECT_LE(2 * watch.period, kWatchdog);
  EXPECT_LE(watch.period + watch.udp.timeout, kWatchdog);
  // Commissioning's loop at its slowest period: a reply is waited for two periods at most,
  // back-off included.
  const auto loop = timing::normal_mode(LinkSettings{}, milliseconds(20), milliseconds(40));
  EXPECT_EQ(loop.udp.timeout, milliseconds(40));
  EXPECT_EQ(loop.udp.max_timeout, milliseconds(40));
}

TEST(Timing, ASessionGivesUpOnMissedRepliesOnlyOnceTheyFillTheWatchdog) {
  // tune-axis's 1 ms loop, replies waited 2 ms: 14 cycles (42 ms) before it gives up; 3 (6 ms)
  // gave up on a card that a host's hiccup kept from answering.
  const auto fast = timing::normal_mode(LinkSettings{}, milliseconds(1), milliseconds(2));
  EXPECT_EQ(fast.max_missed_cycles.get(), 14u);
  EXPECT_GE(fast.max_missed_cycles.get() * (fast.period.get() + milliseconds(2)), kWatchdog);
  // Commissioning's 10 ms loop and the watch: never fewer than kNormalModeMissedCycles.
  EXPECT_EQ(timing::normal_mode(LinkSettings{}, milliseconds(10), milliseconds(20)).max_missed_cycles.get(),
            timing::kNormalModeMissedCycles);
  EXPECT_EQ(timing::normal_mode(LinkSettings{}).max_missed_cycles.get(), timing::kNormalModeMissedCycles);
}

TEST(Timing, OnlyATakeOverTriesASetupStartMoreThanOnce) {
  EXPECT_EQ(timing::running_host(with_timeout(50, false)).setup_start_attempts(), 1u);
  EXPECT_FALSE(timing::passthrough(with_timeout(50, false), {}).running_host.take_over);
  const auto take_over = timing::passthrough(with_timeout(50, true), {});
  EXPECT_TRUE(take_over.running_host.take_over);
  EXPECT_EQ(take_over.running_host.setup_start_attempts(), timing::kTakeOverSetupStarts);
  EXPECT_TRUE(timing::scan(with_timeout(50, true)).running_host.take_over);
  EXPECT_TRUE(timing::normal_mode(with_timeout(50, true)).running_host.take_over);
}

}  // namespace
}  // namespace i20::ops

namespace i20::ops {

// The layers below ops hold no count or wait of their own: none of their option structs can
// be built without the caller's figures (link::Given has no default), so a figure cannot be
// forgotten in ops/core/timing.hpp and silently taken from a lower layer.
TEST(Timing, NoLayerBelowOpsCanBeBuiltWithoutItsFigures) {
  EXPECT_FALSE(std::is_default_constructible_v<link::PipelinedLinkOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<link::SerialOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::UdpOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::FenceOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::SslbpOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::RunningHostCheck>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::PassthroughOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::ScanOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::PassiveOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<eth::NormalModeOptions>);
  EXPECT_FALSE(std::is_default_constructible_v<device::AmpTiming>);
  EXPECT_FALSE(std::is_default_constructible_v<device::DiscoveryOptions>);
  // What ops builds carries its figures: the same ones the header names.
  const auto amp = timing::amp();
  EXPECT_EQ(amp.leave_mode_tries, timing::kLeaveModeTries);
  EXPECT_EQ(amp.reset_poll.get(), timing::kResetPoll);
  const auto serial = timing::serial_link({}, {});
  EXPECT_EQ(serial.max_drain.get(), timing::kSerialMaxDrain);
  const auto port = timing::serial_port({});
  EXPECT_EQ(port.write_slack.get(), timing::kSerialWriteSlack);
  EXPECT_EQ(port.cancel_grace.get(), timing::kSerialCancelGrace);
  const auto passthrough = timing::passthrough({}, {});
  EXPECT_EQ(passthrough.gather_window.get(), timing::kPassthroughGatherWindow);
  EXPECT_EQ(timing::normal_mode({}).zero_cycles_before_stop, timing::kZeroCyclesBeforeStop);
}

}  // namespace i20::ops
