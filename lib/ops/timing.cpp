// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/timing.hpp"

#include <algorithm>

#include "eth/normal_mode.hpp"
#include "eth/passive_reader.hpp"
#include "eth/passthrough_port.hpp"
#include "eth/scan.hpp"
#include "link/pipelined_link.hpp"

namespace i20::ops::timing {

using std::chrono::milliseconds;

link::PipelinedLinkOptions serial_link(const LinkSettings& settings, const RetryPolicy&) {
  link::PipelinedLinkOptions options;
  options.base_timeout = milliseconds(settings.timeout_ms);
  // ops repeats the exchanges itself (Amp::with_retries): a batch is sent once here.
  options.retries = 0;
  return options;
}

eth::UdpOptions udp(const LinkSettings& settings, const RetryPolicy& retry) {
  eth::UdpOptions options;
  options.timeout = milliseconds(settings.timeout_ms);
  options.max_timeout = std::max(kUdpMaxTimeout, options.timeout);
  // Only packets without writes (or vouched idempotent) are resent, within the budget.
  options.retries = retry.resends();
  return options;
}

eth::FenceOptions fence() {
  eth::FenceOptions options;
  options.bound = kFenceBound;
  options.probe_pause = kFenceProbePause;
  options.max_probe_pause = kFenceMaxProbePause;
  return options;
}

eth::SslbpOptions sslbp(const RetryPolicy& retry) {
  eth::SslbpOptions options;
  options.command_timeout = kSslbpCommandTimeout;
  options.poll_pause = kSslbpPollPause;
  options.local_settle = kSslbpLocalSettle;
  // SSLBP commands that a read-only probe found not run: the budget's resends.
  options.lost_reply_retries = retry.resends();
  return options;
}

eth::RunningHostCheck running_host(const LinkSettings& settings) {
  eth::RunningHostCheck check;
  check.take_over = settings.take_over;
  check.window = kRunningHostWindow;
  check.command_samples = kRunningHostCommandSamples;
  check.extra_windows = kRunningHostExtraWindows;
  check.counter_read_attempts = kCounterReadAttempts;
  check.take_over_setup_starts = kTakeOverSetupStarts;
  return check;
}

eth::PassthroughOptions passthrough(const LinkSettings& settings, const RetryPolicy& retry) {
  eth::PassthroughOptions options;
  options.udp = udp(settings, retry);
  options.fence = fence();
  options.sslbp = sslbp(retry);
  options.running_host = running_host(settings);
  // ops repeats the exchanges itself: a passthrough packet whose reply is lost is not sent
  // again by the port (it fences, probes, and reports the loss).
  options.lost_packet_resends = 0;
  options.max_replays = kMaxReplays;
  return options;
}

eth::ScanOptions scan(const LinkSettings& settings, const RetryPolicy& retry) {
  eth::ScanOptions options;
  options.udp = udp(settings, retry);
  options.sslbp = sslbp(retry);
  options.running_host = running_host(settings);
  return options;
}

eth::PassiveOptions passive(const LinkSettings& settings) {
  eth::PassiveOptions options;
  // One attempt per request: a reply a busy host sends late is still taken.
  options.timeout = std::max(milliseconds(settings.timeout_ms), kPassiveReadFloor);
  options.max_timeout = std::max(kUdpMaxTimeout, options.timeout);
  return options;
}

eth::NormalModeOptions normal_mode(const LinkSettings& settings, milliseconds period,
                                   std::optional<milliseconds> reply) {
  eth::NormalModeOptions options;
  options.period = period;
  options.max_missed_cycles = kNormalModeMissedCycles;
  options.udp = udp(settings, RetryPolicy{});
  options.udp.timeout = reply.value_or(kNormalModeReply);
  options.udp.max_timeout = reply.value_or(kUdpMaxTimeout);
  options.sslbp = sslbp(RetryPolicy{});
  options.running_host = running_host(settings);
  return options;
}

}  // namespace i20::ops::timing
