// SPDX-License-Identifier: GPL-2.0-or-later
// Is another host (LinuxCNC, most likely) running the card right now? Asked before any
// operation that stops, starts or re-modes an SSERIAL port: on a running machine a stop
// drops every axis on that port (their 8I20s see no DOIT for 40 ms and disable).
//
// What is measured, over a short window (RunningHostCheck::window, set in ops/core/timing.hpp;
// longer when a little foreign traffic is seen: extra_windows), with read-only packets:
//
//  1. LBP16 space 6 RXUDPCount (0x0A) and TXUDPCount (0x10), read at the start and the end
//     (7I96S/7I92T manuals, "SPACE 6 LBP STATUS/CONTROL AREA"). The card counts every UDP
//     packet it receives and sends; whatever moved beyond our own packets came from, or went
//     to, another host. LinuxCNC's hm2_eth exchanges packets every servo period (1 ms by
//     default), so a running machine shows tens of foreign packets in one window.
//  2. Each SSERIAL port's COMMAND register, sampled a few times in the window. We issue no
//     command during the window, so a non-zero COMMAND is someone else's DOIT (or start)
//     in flight (8I20 manual, "DOIT": SSLBP clears COMMAND when a DOIT completes).
//
// The counters are the evidence that decides; a busy COMMAND is named as corroboration (a
// DOIT lasts a fraction of a servo period, so samples often miss it). The HostMot2
// watchdog is not used: the manuals describe only its LED, and a bitten watchdog says a
// host *was* running, not that one is.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "error/error.hpp"
#include "eth/anything_io.hpp"
#include "eth/transport.hpp"

namespace i20::eth {

// The policy every port-changing operation takes (scan, passthrough open, normal start).
struct RunningHostCheck {
  // Proceed even when another host is using the card. Its machine stops: every axis on
  // the port drops out.
  bool take_over = false;
  // Longer than the 8I20's 40 ms watchdog (8I20 manual, "8I20 DEVICE SPECIFIC SETUP"): a host
  // that keeps an 8I20 running DOITs within every 40 ms, however late its cycles run, so it
  // always shows in the window. 30 ms let a host running late look idle.
  link::Given<std::chrono::milliseconds> window;
  link::Given<unsigned> command_samples;  // COMMAND reads per port spread over the window
  // Foreign packets (received plus sent) in the window above which the card counts as in
  // use. One stray exchange (a mesaflash query from another PC) is tolerated; LinuxCNC's
  // servo loop moves both counters every millisecond, a 10 ms `i20 watch` every 10 ms.
  unsigned foreign_packet_limit = 2;
  // Windows added, one at a time, while foreign packets were seen but no more than the
  // limit. A host that DOITs every 20 ms (the slowest period that keeps the 8I20's 40 ms
  // watchdog fed), or a 10 ms one whose cycles run late on a loaded PC, can show a single
  // exchange in one window, as a stray query does; a longer watch tells them apart. An idle
  // card (nothing foreign) and a host above the limit cost no extra window.
  link::Given<unsigned> extra_windows;
  // How often a counter read is sent again because its request went out more than once
  // (a late reply made the UDP client resend it, and a copy of ours may reach the card
  // between the two counters).
  link::Given<unsigned> counter_read_attempts;
  // Setup starts to try before a channel counts as silent in a take-over: the other host's
  // DOITs can land inside ours and fail a channel that is there. Otherwise one.
  link::Given<unsigned> take_over_setup_starts;
  unsigned setup_start_attempts() const { return take_over ? take_over_setup_starts.get() : 1u; }
};

struct BusyCommand {
  unsigned port = 0;
  std::uint32_t command = 0;
};

struct HostActivity {
  std::chrono::milliseconds window{0};
  std::uint32_t own_packets = 0;       // what we sent between the two counter reads
  std::uint32_t foreign_received = 0;  // RXUDPCount moves beyond our packets
  std::uint32_t foreign_sent = 0;      // TXUDPCount moves beyond our replies
  unsigned command_samples = 0;
  std::vector<BusyCommand> busy{};  // COMMAND seen non-zero
  // RXUDPCount at the last read, and how many packets we had sent by then: the start of
  // the count PassthroughPort keeps to notice a host that talks during its exchanges.
  std::uint16_t last_received = 0;
  std::uint64_t sent_at_last = 0;

  std::uint32_t foreign_packets() const { return foreign_received + foreign_sent; }
  // "the card received 31 UDP packets and sent 30 that were not ours in W ms; SSERIAL
  // port 0 COMMAND was busy with 0x1001 (a DOIT)" or "no other host talked to the card
  // in W ms", W the window watched (ops/core/timing.hpp sets it).
  std::string describe() const;
};

// Refused: another host is running the card. The message names what was seen and how to
// proceed; apps map ErrorKind::Refused to exit code 3.
class RunningHostError : public Error {
 public:
  RunningHostError(const std::string& message, HostActivity activity)
      : Error(message, ErrorKind::Refused, Advice::RunningHost), activity_(std::move(activity)) {}
  const HostActivity& activity() const { return activity_; }

 private:
  HostActivity activity_;
};

// Reads the counters, samples COMMAND of `ports` across the window, reads the counters
// again. Read-only; about 2 + command_samples packets.
HostActivity observe_host_activity(Lbp16Transport& bus, std::span<const SserialPort> ports,
                                   const RunningHostCheck& check);

// Whether `activity` means a host is using the card.
bool host_is_running(const HostActivity& activity, const RunningHostCheck& check);

// Observes the card and throws RunningHostError (ErrorKind::Refused) naming what was seen
// and how to proceed when a host is running and take_over is off. `action` says what we
// were about to do: "stop and setup-start SSERIAL port 0". Returns what was seen either
// way (a take-over is worth a note).
HostActivity require_no_running_host(Lbp16Transport& bus, std::span<const SserialPort> ports,
                                     const RunningHostCheck& check, std::string_view action);

// Packets that reached the card since `since` was observed and were not ours (one
// read-only packet).
std::uint32_t foreign_packets_since(Lbp16Transport& bus, const HostActivity& since,
                                    const RunningHostCheck& check);

}  // namespace i20::eth
