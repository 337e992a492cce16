// SPDX-License-Identifier: GPL-2.0-or-later
// Host side of one SSERIAL port's SSLBP processor (8I20 manual, "SSLBP"): the COMMAND and
// DATA registers, local parameters, and the per-channel CS/INTERFACE registers.
//
// Every operation has the same shape: write some registers, write COMMAND, then read
// COMMAND back until it is 0 and take DATA and whatever else the caller needs. The
// writes and the first read-back share one packet; on LBP16 version 3 cards a WaituS
// write (space 4) between them lets quick commands finish inside that packet, so most
// operations cost one round trip. Polling continues with read-only packets until a
// deadline.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "eth/anything_io.hpp"
#include "eth/transport.hpp"
#include "hostmot2/hostmot2.hpp"

namespace i20::eth {

struct SslbpOptions {
  // A start probes every selected channel and "may be many mS" (manual): allow 2 s.
  link::Given<std::chrono::milliseconds> command_timeout;
  // Pause between read-back polls after the first repeat, so a slow start is not
  // answered by a flood of packets.
  link::Given<std::chrono::microseconds> poll_pause;
  // WaituS after a local parameter request or a stop: SSLBP's processor answers those
  // in microseconds, so the read-back in the same packet normally finds them done.
  link::Given<std::chrono::microseconds> local_settle;
  // How often an SSLBP command's packet (it holds writes) is resent when its reply is lost
  // and the operation is repeatable, only after a read-only probe found COMMAND idle. Only
  // SslbpPort::run's own commands: passthrough packets follow
  // PassthroughOptions::lost_packet_resends. ops hands down its budget's resends. (A
  // command that found COMMAND busy with another one is issued again once it is idle,
  // within command_timeout: that is waiting for the port, not a lost reply.)
  link::Given<unsigned> lost_reply_retries;
};

struct SslbpParameters {
  std::uint8_t interface_type = 0;
  std::uint8_t width = 0;
  std::uint8_t version_major = 0;
  std::uint8_t version_minor = 0;
  std::uint8_t channel_start = 0;
  std::uint8_t channel_stride = 0;
  std::uint8_t processor_type = 0;
  std::uint8_t channels = 0;
  std::uint32_t clock_hz = 0;

  std::string version() const { return std::to_string(version_major) + "." + std::to_string(version_minor); }
};

struct ChannelRegisters {
  std::uint32_t cs = 0;
  std::uint32_t interface0 = 0;  // unit number after a start
  std::uint32_t interface1 = 0;  // card name after a start ("8I20" = 0x30324938)
  std::uint32_t interface2 = 0;

  lbp::hm2::sslbp::ChannelStatus status() const { return {cs}; }
  std::string name() const { return lbp::hm2::sslbp::name_of_word(interface1); }
};

struct Completion {
  std::uint8_t data = 0;                 // DATA after COMMAND cleared
  std::vector<std::uint32_t> results{};  // the requested registers, same order
  unsigned round_trips = 0;
  // Packets of another host's that reached the card between our command and the read that
  // found it done (SslbpPort::run's own polls only): that host may have run a command of its
  // own in between, whose DATA we read.
  std::uint32_t foreign_packets = 0;
};

class SslbpPort {
 public:
  // `timer_space`: the card has LBP16 space 4 (BoardIdentity::has_timer_space()).
  SslbpPort(Lbp16Transport& bus, SserialPort port, bool timer_space, SslbpOptions options);

  // The general operation: `before` (register writes), COMMAND = `command`, a WaituS of
  // `settle` when the card has the timer space, then COMMAND, DATA and `results` read
  // back until COMMAND is 0. `repeatable`: executing the operation twice is harmless, so
  // it may be resent when its reply is lost. Throws link::TimeoutError when COMMAND does
  // not clear in time or the card stops answering, and ForeignHostError when another
  // command held COMMAND at every write for command_timeout (its DATA is never returned), or
  // when another host's packet reached the card while ours ran and the command cannot be
  // run again (a repeatable one is, within command_timeout).
  Completion run(std::span<const lbp::lbp16::Command> before, std::uint32_t command,
                 std::span<const std::uint16_t> results, bool repeatable,
                 std::chrono::microseconds settle = std::chrono::microseconds{0});
  // COMMAND alone; returns DATA.
  std::uint8_t run(std::uint32_t command);

  // Waits for COMMAND to read 0 (after an error left it busy). False on timeout.
  bool wait_idle();
  // Read-only polls of COMMAND, DATA and `results` until COMMAND reads 0; throws
  // link::TimeoutError naming `command` after SslbpOptions::command_timeout.
  // `round_trips` is added to the count the completion reports.
  Completion poll(std::span<const std::uint16_t> results, std::uint32_t command, unsigned round_trips = 0);

  void stop_all();
  // Return DATA: a set bit marks a channel that failed to start.
  std::uint8_t start_setup(std::uint8_t mask);
  // start_setup, and while a channel failed, stop_all and start again: `attempts` starts in
  // all (RunningHostCheck::setup_start_attempts).
  std::uint8_t start_setup(std::uint8_t mask, unsigned attempts);
  std::uint8_t start_normal(std::uint8_t mask);

  std::uint8_t read_local(std::uint16_t address);
  std::uint32_t read_local32(std::uint16_t address);  // little endian, 4 local reads
  SslbpParameters read_parameters();
  // The baud rate SSLBP uses towards `channel` (0 when the firmware does not say).
  std::uint32_t read_baud_rate(const SslbpParameters& parameters, unsigned channel);

  // CS, INTERFACE0..2 of the channels in `mask`, one packet.
  std::vector<ChannelRegisters> read_channels(std::uint8_t mask);

  const SserialPort& port() const { return port_; }
  Lbp16Transport& bus() { return bus_; }
  bool timer_space() const { return timer_space_; }
  const SslbpOptions& options() const { return options_; }
  // "192.168.1.121 SSERIAL port 0", for messages.
  std::string describe() const;

 private:
  struct Reading {
    std::uint32_t command = 0;
    Completion completion;
  };
  // The card's count of packets received (space 6 RXUDPCount) as one of our packets found it,
  // and how many packets we had sent by then.
  struct Arrivals {
    std::uint16_t received = 0;
    std::uint64_t sent = 0;
  };
  static Arrivals arrivals_of(const std::vector<lbp::Bytes>& parts, std::uint64_t sent);
  // poll(); with `since`, each poll reads RXUDPCount too and the completion counts the packets
  // that reached the card after `since` and were not ours.
  Completion poll_until_idle(std::span<const std::uint16_t> results, std::uint32_t command,
                             unsigned round_trips, std::optional<Arrivals> since);
  Reading parse(const std::vector<lbp::Bytes>& parts, std::size_t first, std::size_t results) const;
  // COMMAND, DATA and `results`; `counted`: RXUDPCount first.
  std::vector<lbp::lbp16::Command> read_back(std::span<const std::uint16_t> results,
                                             bool counted = false) const;

  Lbp16Transport& bus_;
  SserialPort port_;
  bool timer_space_;
  SslbpOptions options_;
};

}  // namespace i20::eth
