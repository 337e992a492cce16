// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/sslbp_port.hpp"

#include <algorithm>
#include <optional>
#include <thread>

#include "eth/errors.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace sslbp = lbp::hm2::sslbp;
using Clock = std::chrono::steady_clock;

namespace {

// A register's value from its reply bytes.
constexpr auto word = lbp::read_le32;

}  // namespace

SslbpPort::SslbpPort(Lbp16Transport& bus, SserialPort port, bool timer_space, SslbpOptions options)
    : bus_(bus), port_(port), timer_space_(timer_space), options_(options) {}

std::string SslbpPort::describe() const {
  return bus_.describe() + " SSERIAL port " + std::to_string(port_.index);
}

std::vector<lbp16::Command> SslbpPort::read_back(std::span<const std::uint16_t> results, bool counted) const {
  std::vector<lbp16::Command> reads;
  if (counted) reads.push_back(received_count_read());
  reads.push_back(lbp16::read_hm2(port_.registers.command));
  reads.push_back(lbp16::read_hm2(port_.registers.data));
  for (std::uint16_t address : results) reads.push_back(lbp16::read_hm2(address));
  return reads;
}

SslbpPort::Reading SslbpPort::parse(const std::vector<lbp::Bytes>& parts, std::size_t first,
                                    std::size_t results) const {
  Reading r;
  r.command = word(parts[first]) & 0xFFFF;  // 16 bits, right justified
  r.completion.data = static_cast<std::uint8_t>(word(parts[first + 1]));
  for (std::size_t i = 0; i < results; ++i) r.completion.results.push_back(word(parts[first + 2 + i]));
  return r;
}

Completion SslbpPort::run(std::span<const lbp16::Command> before, std::uint32_t command,
                          std::span<const std::uint16_t> results, bool repeatable,
                          std::chrono::microseconds settle) {
  // RXUDPCount first: a result read in a later packet is ours only if no other packet reached
  // the card in between (poll_until_idle).
  std::vector<lbp16::Command> packet{received_count_read()};
  packet.insert(packet.end(), before.begin(), before.end());
  // COMMAND as our write finds it, in the same packet (the card runs a packet's commands
  // back to back, so no other host's write falls between the two): SSLBP ignores a command
  // written while it is busy, and the busy one may finish before our read-back, leaving
  // COMMAND idle and its DATA where ours would be. Only this read tells ours ran.
  const std::size_t at_write = packet.size();
  packet.push_back(lbp16::read_hm2(port_.registers.command));
  packet.push_back(lbp16::write_hm2(port_.registers.command, command));
  if (timer_space_ && settle.count() > 0) {
    const auto us = static_cast<std::uint16_t>(std::min<std::int64_t>(settle.count(), 0xFFFF));
    packet.push_back(lbp16::write(lbp16::space::kTimers, kWaitMicrosecondsAddress, lbp16::Width::Bits16,
                                  lbp::to_le(us, 2), false));
  }
  const std::size_t first_read = packet.size();
  const auto reads = read_back(results);
  packet.insert(packet.end(), reads.begin(), reads.end());

  // A command displaced by another one is issued again once COMMAND is idle, for as long as
  // the command itself may take; past that the port is another host's, and what it finished
  // is never taken for ours. So is a repeatable command whose result another host's packet
  // may have replaced.
  const auto displaced_until = Clock::now() + options_.command_timeout;
  unsigned round_trips = 0;
  unsigned displaced = 0;
  const auto ours_unless_disturbed = [&](const Completion& c) {
    if (c.foreign_packets == 0) return true;
    if (!repeatable || Clock::now() >= displaced_until)
      throw ForeignHostError("another host sent " + std::to_string(c.foreign_packets) + " packet(s) to " +
                             describe() + " while SSLBP command " + lbp::hex_value(command, 4) +
                             " ran: what DATA held may be that host's result, so it was discarded " +
                             "(LinuxCNC running?)");
    round_trips = c.round_trips;
    return false;
  };
  for (unsigned attempt = 0;; ++attempt) {
    try {
      ++round_trips;
      std::uint64_t sent = 0;
      const auto parts = bus_.transact_counted(packet, Resend::Never, sent);
      const std::uint32_t busy_at_write = word(parts[at_write]) & 0xFFFF;
      const Reading r = parse(parts, first_read, results.size());
      if (busy_at_write == 0 && r.command == 0) {
        Completion c = r.completion;
        c.round_trips = round_trips;
        return c;
      }
      if (busy_at_write != 0 || r.command != (command & 0xFFFF)) {
        const std::uint32_t other = busy_at_write != 0 ? busy_at_write : r.command;
        ++displaced;
        if (Clock::now() >= displaced_until)
          throw ForeignHostError("SSLBP on " + describe() + " was running another command (" +
                                 lbp::hex_value(other, 4) + ") each time SSLBP command " +
                                 lbp::hex_value(command, 4) + " was written (" + std::to_string(displaced) +
                                 " times in " + std::to_string(options_.command_timeout.count()) +
                                 " ms): another host keeps the port busy, and its results are not ours");
        round_trips = poll({}, other, round_trips).round_trips;
        continue;
      }
      const Completion c = poll_until_idle(results, command, round_trips, arrivals_of(parts, sent));
      if (ours_unless_disturbed(c)) return c;
    } catch (const link::TimeoutError&) {
      // The reply is lost, the packet maybe too. A read-only probe tells which: a busy
      // COMMAND means it arrived and is running.
      ++round_trips;
      std::uint64_t sent = 0;
      const auto parts = bus_.transact_counted(read_back(results, true), Resend::IfReadOnly, sent);
      const Reading probe = parse(parts, 1, results.size());
      if (probe.command != 0) {
        const Completion c = poll_until_idle(results, command, round_trips, arrivals_of(parts, sent));
        if (ours_unless_disturbed(c)) return c;
        continue;
      }
      if (!repeatable || attempt >= options_.lost_reply_retries)
        throw link::TimeoutError("the reply to SSLBP command " + lbp::hex_value(command, 4) + " on " +
                                 describe() + " was lost and the command " +
                                 (repeatable
                                      ? "still got no answer when resent"
                                      : "cannot be resent safely: it may or may not have taken effect"));
    }
  }
}

SslbpPort::Arrivals SslbpPort::arrivals_of(const std::vector<lbp::Bytes>& parts, std::uint64_t sent) {
  return Arrivals{.received = static_cast<std::uint16_t>(word(parts.front())), .sent = sent};
}

Completion SslbpPort::poll(std::span<const std::uint16_t> results, std::uint32_t command,
                           unsigned round_trips) {
  return poll_until_idle(results, command, round_trips, std::nullopt);
}

Completion SslbpPort::poll_until_idle(std::span<const std::uint16_t> results, std::uint32_t command,
                                      unsigned round_trips, std::optional<Arrivals> since) {
  const auto deadline = Clock::now() + options_.command_timeout;
  const auto reads = read_back(results, since.has_value());
  const std::size_t first = since ? 1 : 0;
  for (unsigned polls = 0;; ++polls) {
    if (polls > 0) std::this_thread::sleep_for(options_.poll_pause);
    ++round_trips;
    std::uint64_t sent = 0;
    const auto parts = bus_.transact_counted(reads, Resend::IfReadOnly, sent);
    const Reading r = parse(parts, first, results.size());
    if (r.command == 0) {
      Completion c = r.completion;
      c.round_trips = round_trips;
      if (since) {
        // Packets the card received since `since`, beyond ours (resends included: a copy
        // that never arrived can hide one of another host's, never invent one).
        const std::uint32_t moved =
            static_cast<std::uint16_t>(arrivals_of(parts, sent).received - since->received);
        const std::uint64_t ours = sent - since->sent;
        c.foreign_packets = moved > ours ? static_cast<std::uint32_t>(moved - ours) : 0;
      }
      return c;
    }
    if (Clock::now() >= deadline)
      throw link::TimeoutError("SSLBP on " + describe() + " did not finish command " +
                               lbp::hex_value(command, 4) + " within " +
                               std::to_string(options_.command_timeout.count()) +
                               " ms (COMMAND still reads " + lbp::hex_value(r.command, 4) + ")");
  }
}

std::uint8_t SslbpPort::run(std::uint32_t command) {
  // Local requests and stops are the processor's own business: microseconds. Starts talk
  // to every remote and take milliseconds: those are polled.
  const bool quick =
      (command & sslbp::kRequest) || (command & (sslbp::kStart | sslbp::kTypeMask)) == sslbp::kStop;
  return run({}, command, {}, /*repeatable=*/true,
             quick ? options_.local_settle : std::chrono::microseconds{0})
      .data;
}

bool SslbpPort::wait_idle() {
  try {
    poll({}, 0, 0);
    return true;
  } catch (const link::TimeoutError&) {
    return false;
  }
}

void SslbpPort::stop_all() {
  run(sslbp::stop());
}

std::uint8_t SslbpPort::start_setup(std::uint8_t mask) {
  return run(sslbp::start_setup(mask));
}

std::uint8_t SslbpPort::start_setup(std::uint8_t mask, unsigned attempts) {
  std::uint8_t failed = start_setup(mask);
  for (unsigned attempt = 1; failed != 0 && attempt < attempts; ++attempt) {
    stop_all();
    failed = start_setup(mask);
  }
  return failed;
}

std::uint8_t SslbpPort::start_normal(std::uint8_t mask) {
  return run(sslbp::start_normal(mask));
}

std::uint8_t SslbpPort::read_local(std::uint16_t address) {
  return run(sslbp::read_local(address));
}

std::uint32_t SslbpPort::read_local32(std::uint16_t address) {
  std::uint32_t value = 0;
  for (unsigned i = 0; i < 4; ++i)
    value |= std::uint32_t{read_local(static_cast<std::uint16_t>(address + i))} << (8 * i);
  return value;
}

SslbpParameters SslbpPort::read_parameters() {
  namespace param = sslbp::param;
  SslbpParameters p;
  p.interface_type = read_local(param::kInterfaceType);
  p.width = read_local(param::kWidth);
  p.version_major = read_local(param::kMajorVersion);
  p.version_minor = read_local(param::kMinorVersion);
  p.channel_start = read_local(param::kChannelStart);
  p.channel_stride = read_local(param::kChannelStride);
  p.processor_type = read_local(param::kProcessorType);
  p.channels = read_local(param::kChannels);
  p.clock_hz = read_local32(param::kClock);
  return p;
}

std::uint32_t SslbpPort::read_baud_rate(const SslbpParameters& parameters, unsigned channel) {
  const unsigned address =
      parameters.channel_start + channel * parameters.channel_stride + sslbp::param::kBaudRateOffset;
  if (parameters.channel_start == 0 || address + 4 > sslbp::kLocalAddressMask + 1) return 0;
  return read_local32(static_cast<std::uint16_t>(address));
}

std::vector<ChannelRegisters> SslbpPort::read_channels(std::uint8_t mask) {
  std::vector<lbp16::Command> reads;
  std::vector<unsigned> channels;
  for (unsigned ch = 0; ch < 8; ++ch) {
    if (!(mask & (1u << ch))) continue;
    channels.push_back(ch);
    for (std::uint16_t a : {port_.registers.cs(ch), port_.registers.interface0(ch),
                            port_.registers.interface1(ch), port_.registers.interface2(ch)})
      reads.push_back(lbp16::read_hm2(a));
  }
  if (reads.empty()) return {};
  const auto parts = bus_.transact(reads);
  std::vector<ChannelRegisters> out;
  for (std::size_t i = 0; i < channels.size(); ++i)
    out.push_back(ChannelRegisters{.cs = word(parts[4 * i]),
                                   .interface0 = word(parts[4 * i + 1]),
                                   .interface1 = word(parts[4 * i + 2]),
                                   .interface2 = word(parts[4 * i + 3])});
  return out;
}

}  // namespace i20::eth
