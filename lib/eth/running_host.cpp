// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/running_host.hpp"

#include <algorithm>
#include <optional>
#include <thread>

#include "eth/batched_opening.hpp"
#include "eth/errors.hpp"
#include "hostmot2/hostmot2.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace sslbp = lbp::hm2::sslbp;

namespace {

struct Counters {
  std::uint16_t received = 0;
  std::uint16_t sent = 0;
};

lbp16::Command counters_read() {
  return udp_counters_read();
}

Counters counters_of(const lbp::Bytes& words) {
  const auto w = lbp16::words16(words);
  return Counters{.received = w.front(), .sent = w.back()};
}

// `packet` (read-only) as transact_counted(). With `counters`, until one request went out
// once: a request resent after a late reply leaves a copy of ours that may reach the card
// after the copy whose counters we took. Counted from the first read of the window, that
// copy would look like another host's packet (an idle card "in use": a resend on a loaded
// host did it); counted in `sent` at the last read, it would hide one of another host's.
// A read sent after every copy counts them all (one path to the card: they arrive in
// order), so the counters are read again.
std::vector<lbp::Bytes> transact_for_counters(Lbp16Transport& bus, std::span<const lbp16::Command> packet,
                                              bool counters, std::uint64_t& sent, unsigned attempts) {
  for (unsigned attempt = 1;; ++attempt) {
    const auto resends = bus.stats().resends;
    auto parts = bus.transact_counted(packet, Resend::IfReadOnly, sent);
    if (!counters || bus.stats().resends == resends || attempt >= attempts) return parts;
  }
}

// One read-only packet: optionally the counters, then COMMAND of every port. Returns the
// counters when asked for and records busy COMMANDs.
std::optional<Counters> sample(Lbp16Transport& bus, std::span<const SserialPort> ports, bool counters,
                               const RunningHostCheck& check, HostActivity& activity, std::uint64_t& sent) {
  std::vector<lbp16::Command> packet;
  if (counters) packet.push_back(counters_read());
  for (const auto& port : ports) packet.push_back(lbp16::read_hm2(port.registers.command));
  const auto parts = transact_for_counters(bus, packet, counters, sent, check.counter_read_attempts);
  const std::size_t first = counters ? 1 : 0;
  for (std::size_t i = 0; i < ports.size(); ++i) {
    const auto command = static_cast<std::uint32_t>(lbp::read_le(parts[first + i])) & 0xFFFF;
    if (command != 0) activity.busy.push_back(BusyCommand{.port = ports[i].index, .command = command});
  }
  ++activity.command_samples;
  if (!counters) return std::nullopt;
  return counters_of(parts.front());
}

// Our requests delayed past their resend that may reach the card inside a watch window (CI's
// mild network faults: a few in a run). More are not taken off: another host's packets could
// hide behind them.
constexpr std::uint64_t kMostLateOwnPackets = 2;

std::uint32_t beyond(std::uint16_t before, std::uint16_t after, std::uint32_t own) {
  const std::uint32_t moved = static_cast<std::uint16_t>(after - before);  // the counters wrap at 16 bits
  return moved > own ? moved - own : 0;
}

std::string what_command_is(std::uint32_t command) {
  if (command & sslbp::kDoit) return "a DOIT";
  if ((command & (sslbp::kStart | sslbp::kTypeMask)) == sslbp::kStartNormal) return "a normal start";
  if ((command & (sslbp::kStart | sslbp::kTypeMask)) == sslbp::kStartSetup) return "a setup start";
  if (command & sslbp::kRequest) return "a local parameter access";
  return "a command";
}

// The window from `start` on: command_samples - 1 COMMAND samples spread over it, then the
// last sample with the counters at its end. `unarrived`: packets of ours the card had not
// counted at the first counter read (TransportStats::unarrived); arriving in the window, each
// moves both counters (its reply too) and is ours, not another host's. At most
// kMostLateOwnPackets of them are taken off the count, and only for the verdict: any packet
// not ours keeps the watch going for its extra windows, so a host that keeps talking (a slow
// one shows a dozen packets in them) is still seen past them.
HostActivity finish_window(Lbp16Transport& bus, std::span<const SserialPort> ports,
                           const RunningHostCheck& check, HostActivity activity,
                           std::chrono::steady_clock::time_point start, Counters first,
                           std::uint64_t sent_after_first, std::uint64_t unarrived) {
  const unsigned between = std::max(1u, check.command_samples.get()) - 1;
  std::uint64_t sent = 0;
  const auto step = check.window / (between + 1);
  for (unsigned i = 0; i < between; ++i) {
    std::this_thread::sleep_until(start + step * (i + 1));
    sample(bus, ports, false, check, activity, sent);
  }
  auto end = start + check.window;
  for (unsigned extra = 0;; ++extra) {
    std::this_thread::sleep_until(end);
    const Counters last = *sample(bus, ports, true, check, activity, sent);
    activity.window =
        std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start);
    // Every packet we sent after the first counter read was counted on the way in; every
    // reply from the first one on was counted on the way out.
    activity.own_packets = static_cast<std::uint32_t>(sent - sent_after_first);
    const std::uint32_t received = beyond(first.received, last.received, activity.own_packets);
    const std::uint32_t replied = beyond(first.sent, last.sent, activity.own_packets);
    const auto late_own = static_cast<std::uint32_t>(std::min<std::uint64_t>(unarrived, kMostLateOwnPackets));
    activity.foreign_received = received - std::min(received, late_own);
    activity.foreign_sent = replied - std::min(replied, late_own);
    activity.last_received = last.received;
    activity.sent_at_last = sent;
    // Another host seen, but not above the limit: a stray query, or a host that talks less
    // often than the window is long (see extra_windows). Watch on before deciding.
    const std::uint32_t foreign = activity.foreign_packets();
    if (received + replied == 0 || foreign > check.foreign_packet_limit || extra == check.extra_windows)
      return activity;
    end += check.window;
  }
}

HostActivity refuse_if_running(Lbp16Transport& bus, const RunningHostCheck& check, std::string_view action,
                               HostActivity activity) {
  if (check.take_over || !host_is_running(activity, check)) return activity;
  std::string message = "refusing to " + std::string(action) + " on " + bus.describe();
  message += ": another host is running the card (" + activity.describe() + "). ";
  // What the user may do, in words: the option that says it is the app's to name
  // (ops::Advice::RunningHost).
  message += "Stop LinuxCNC first, or take the port over: every axis on that port drops out";
  throw RunningHostError(message, activity);
}

}  // namespace

// RXUDPCount (0x0A) through TXUDPCount (0x10): four 16-bit words in one command.
lbp16::Command udp_counters_read() {
  return lbp16::read(lbp16::space::kStatus, kRxUdpCountAddress, lbp16::Width::Bits16,
                     (kTxUdpCountAddress - kRxUdpCountAddress) / 2 + 1);
}

HostActivity require_no_running_host(Lbp16Transport& bus, std::span<const SserialPort> ports,
                                     const RunningHostCheck& check, std::string_view action,
                                     const CounterSample& first) {
  // A survey sent more than once opens no window (transact_for_counters): a window of its own.
  if (!first.sent_once) return require_no_running_host(bus, ports, check, action);
  return refuse_if_running(bus, check, action,
                           finish_window(bus, ports, check, HostActivity{}, first.at,
                                         counters_of(first.reply), first.sent, first.unarrived));
}

std::string HostActivity::describe() const {
  const std::string in = " in " + std::to_string(window.count()) + " ms";
  std::string s;
  if (foreign_packets() == 0) {
    s = "no other host talked to the card" + in;
  } else {
    s = "the card received " + std::to_string(foreign_received) + " and sent " +
        std::to_string(foreign_sent) + " UDP packets that were not ours" + in;
  }
  if (!busy.empty()) {
    const BusyCommand& b = busy.front();
    s += "; SSERIAL port " + std::to_string(b.port);
    s += " COMMAND was busy with " + lbp::hex_value(b.command, 4);
    s += " (" + what_command_is(b.command) + ") in ";
    s += std::to_string(busy.size()) + " of " + std::to_string(command_samples) + " samples";
  }
  return s;
}

HostActivity observe_host_activity(Lbp16Transport& bus, std::span<const SserialPort> ports,
                                   const RunningHostCheck& check) {
  HostActivity activity;
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t sent_after_first = 0;
  const Counters first = *sample(bus, ports, true, check, activity, sent_after_first);
  return finish_window(bus, ports, check, std::move(activity), start, first, sent_after_first,
                       bus.stats().unarrived);
}

std::uint32_t foreign_packets_since(Lbp16Transport& bus, const HostActivity& since,
                                    const RunningHostCheck& check) {
  const lbp16::Command read = counters_read();
  std::uint64_t sent = 0;
  const Counters now = counters_of(
      transact_for_counters(bus, std::span(&read, 1), true, sent, check.counter_read_attempts).front());
  const std::uint64_t ours = sent - since.sent_at_last;
  return beyond(since.last_received, now.received, static_cast<std::uint32_t>(ours));
}

bool host_is_running(const HostActivity& activity, const RunningHostCheck& check) {
  return activity.foreign_packets() > check.foreign_packet_limit;
}

HostActivity require_no_running_host(Lbp16Transport& bus, std::span<const SserialPort> ports,
                                     const RunningHostCheck& check, std::string_view action) {
  return refuse_if_running(bus, check, action, observe_host_activity(bus, ports, check));
}

}  // namespace i20::eth
