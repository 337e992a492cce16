// SPDX-License-Identifier: GPL-2.0-or-later
// Opening a setup-mode passthrough in few UDP requests (issue 18 item 5). LBP16 carries
// several commands in one request (7I96S/7I92T manuals, "LBP16"), and WaituS (space 4)
// lets one request hold SSLBP operations that follow each other. What used to be 30-odd
// requests, one read at a time, becomes:
//
//   1. identification, the HostMot2 cookie area and the IDROM with its tables at their
//      usual place, and the running-host watch's first counter read   (survey_board)
//   2. the watch's last counter read at the window's end (ops/core/timing.hpp), with its COMMAND sample
//   3. stop, SSLBP's parameters                                      (read_locals)
//   4. stop, the remotes' baud rates, the setup start, the channels' registers
//
// and the command itself, and the stop at the end. Each 8I20's NV access and RPC memory
// modes are learnt from the device layer's own reads of them (its first batch), not read
// again here. Each batch checks its own results (run_sequence); where a check fails, the
// operations run again one at a time, so a batch can cost packets but never a wrong value.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "eth/anything_io.hpp"
#include "eth/running_host.hpp"
#include "eth/sslbp_port.hpp"

namespace i20::eth {

// identify() and read_hostmot2() in one read-only request where HostMot2 keeps its IDROM
// (0x400, the module and pin tables at their usual offsets); otherwise, read_hostmot2()
// after it. `extra` reads ride along in that request; their data is in extra_replies.
struct BoardSurvey {
  BoardIdentity identity{};
  HostMot2Info hostmot2{};
  std::vector<lbp::Bytes> extra_replies{};
  std::uint64_t sent = 0;       // our packets once that one was sent (transact_counted)
  bool sent_once = true;        // that request went out once (no resend after a late reply)
  std::uint64_t unarrived = 0;  // packets of ours the card had not counted then (TransportStats)
  std::chrono::steady_clock::time_point replied_at{};
};
BoardSurvey survey_board(Lbp16Transport& bus, std::span<const lbp::lbp16::Command> extra = {});

// RXUDPCount through TXUDPCount, one read: the running-host watch's counters.
lbp::lbp16::Command udp_counters_read();

// The watch's first counter read when it travelled in an earlier request (survey_board's
// extra reads): its reply, our packet count then and the time of the reply. A request
// sent more than once opens no window (a copy of ours may reach the card after the read):
// the watch then reads the counters again first.
struct CounterSample {
  lbp::Bytes reply{};
  std::uint64_t sent = 0;
  std::chrono::steady_clock::time_point at{};
  bool sent_once = true;
  std::uint64_t unarrived = 0;  // packets of ours the card had not counted at that read
};
// require_no_running_host() with the window opened by `first`: command_samples - 1 COMMAND
// samples inside it and the last counter read (with a COMMAND sample) at its end. The host
// sleeps between the samples: the card must not wait (WaituS) there, because a card that
// waits serves no other host, and the watch runs before we know that none is running.
HostActivity require_no_running_host(Lbp16Transport& bus, std::span<const SserialPort> ports,
                                     const RunningHostCheck& check, std::string_view action,
                                     const CounterSample& first);

// One SSLBP operation of a sequence: COMMAND, the WaituS after it, the registers read back.
struct SslbpStep {
  std::uint32_t command = 0;
  std::chrono::microseconds settle{0};
  std::vector<std::uint16_t> results{};
};
// Repeatable operations (stops, starts, local reads) in one request when the card has the
// timer space. A step's results are trusted only when the step before it read back idle
// (a command written while SSLBP is busy is not one to trust) and its own COMMAND read 0;
// from the first busy step on they run again one at a time (SslbpPort::run), except a busy
// last step, which was accepted and is polled for its own result.
std::vector<Completion> run_sequence(SslbpPort& sslbp, std::span<const SslbpStep> steps);
// Local parameter reads (a stop first, when asked) as one sequence; their DATA.
std::vector<std::uint8_t> read_locals(SslbpPort& sslbp, std::span<const std::uint16_t> addresses,
                                      bool stop_first);
// SslbpPort::read_parameters() after a stop, as one sequence.
SslbpParameters stop_and_read_parameters(SslbpPort& sslbp);
// Where SSLBP keeps `channel`'s baud rate among its local parameters (4 bytes, little
// endian), when the firmware says (SslbpPort::read_baud_rate reads the same place).
std::optional<std::uint16_t> baud_rate_address(const SslbpParameters& parameters, unsigned channel);

}  // namespace i20::eth
