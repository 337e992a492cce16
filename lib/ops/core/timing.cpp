// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/timing.hpp"

#include <algorithm>

#include "device/amp.hpp"
#include "eth/normal_mode.hpp"
#include "eth/passive_reader.hpp"
#include "eth/passthrough_port.hpp"
#include "eth/scan.hpp"
#include "link/pipelined_link.hpp"
#include "link/serial_stream.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/retry.hpp"

namespace i20::ops::timing {

using std::chrono::milliseconds;

device::AmpTiming amp() {
  return {.leave_mode_tries = kLeaveModeTries, .reset_poll = kResetPoll, .clear_fault_poll = kClearFaultPoll};
}

link::PipelinedLinkOptions serial_link(const LinkSettings& settings, const RetryPolicy&) {
  return {
      .base_timeout = milliseconds(settings.timeout_ms),
      // ops repeats the exchanges itself (Amp::with_retries): a batch is sent once here.
      .retries = 0u,
      .max_drain = kSerialMaxDrain,
  };
}

link::SerialOptions serial_port(const LinkSettings& settings) {
  return {.baud = settings.baud, .write_slack = kSerialWriteSlack, .cancel_grace = kSerialCancelGrace};
}

eth::UdpOptions udp(const LinkSettings& settings, const RetryPolicy& retry) {
  const milliseconds timeout(settings.timeout_ms);
  return {
      .timeout = timeout,
      .max_timeout = std::max(kUdpMaxTimeout, timeout),
      // Only packets without writes (or vouched idempotent) are resent, within the budget.
      .retries = retry.resends(),
  };
}

eth::FenceOptions fence() {
  return {.bound = kFenceBound, .probe_pause = kFenceProbePause, .max_probe_pause = kFenceMaxProbePause};
}

eth::SslbpOptions sslbp(const RetryPolicy& retry) {
  return {
      .command_timeout = kSslbpCommandTimeout,
      .poll_pause = kSslbpPollPause,
      .local_settle = kSslbpLocalSettle,
      // SSLBP commands that a read-only probe found not run: the budget's resends.
      .lost_reply_retries = retry.resends(),
  };
}

eth::RunningHostCheck running_host(const LinkSettings& settings) {
  return {
      .take_over = settings.take_over,
      .window = kRunningHostWindow,
      .command_samples = kRunningHostCommandSamples,
      .extra_windows = kRunningHostExtraWindows,
      .counter_read_attempts = kCounterReadAttempts,
      .take_over_setup_starts = kTakeOverSetupStarts,
  };
}

eth::PassthroughOptions passthrough(const LinkSettings& settings, const RetryPolicy& retry) {
  return {
      .udp = udp(settings, retry),
      .fence = fence(),
      .sslbp = sslbp(retry),
      // ops repeats the exchanges itself: a passthrough packet whose reply is lost is not
      // sent again by the port (it fences, probes, and reports the loss).
      .lost_packet_resends = 0u,
      .running_host = running_host(settings),
      .max_packet_wait = kPassthroughMaxPacketWait,
      .max_slack = kPassthroughMaxSlack,
      .gather_window = kPassthroughGatherWindow,
      .max_replays = kMaxReplays,
      .close_budget = kPortCloseBudget,
      .opening_attempts = retry.attempts,
  };
}

eth::ScanOptions scan(const LinkSettings& settings) {
  return scan(settings, RetryPolicy{});
}

eth::ScanOptions scan(const LinkSettings& settings, const RetryPolicy& retry) {
  return {.udp = udp(settings, retry), .sslbp = sslbp(retry), .running_host = running_host(settings)};
}

eth::PassiveOptions passive(const LinkSettings& settings) {
  // One attempt per request: a reply a busy host sends late is still taken.
  const milliseconds timeout = std::max(milliseconds(settings.timeout_ms), kPassiveReadFloor);
  return {
      .max_requests_per_second = kPassiveMaxRequestsPerSecond,
      .timeout = timeout,
      .max_timeout = std::max(kUdpMaxTimeout, timeout),
  };
}

namespace {
// kNormalModeMissedCycles, or as many cycles (each its period and its reply's longest wait) as
// the 8I20's watchdog lasts, whichever is more: a session gives up only once the card has
// likely stopped its output.
unsigned missed_cycles(milliseconds period, milliseconds reply) {
  const auto cycle = period + reply;
  const auto fill = static_cast<unsigned>((kEightI20Watchdog + cycle - milliseconds(1)) / cycle);
  return std::max(kNormalModeMissedCycles, fill);
}
}  // namespace

eth::NormalModeOptions normal_mode(const LinkSettings& settings, milliseconds period,
                                   std::optional<milliseconds> reply) {
  eth::UdpOptions reply_wait = udp(settings, RetryPolicy{});
  reply_wait.timeout = reply.value_or(kNormalModeReply);
  reply_wait.max_timeout = reply.value_or(kUdpMaxTimeout);
  return {
      .udp = reply_wait,
      .sslbp = sslbp(RetryPolicy{}),
      .running_host = running_host(settings),
      .period = period,
      .max_missed_cycles = missed_cycles(period, reply.value_or(kUdpMaxTimeout)),
      .zero_cycles_before_stop = kZeroCyclesBeforeStop,
  };
}

}  // namespace i20::ops::timing
