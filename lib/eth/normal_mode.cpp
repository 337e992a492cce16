// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/normal_mode.hpp"

#include <algorithm>

#include "eth/errors.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace sslbp = lbp::hm2::sslbp;
using Clock = std::chrono::steady_clock;

namespace {

std::vector<unsigned> channels_of(std::uint8_t mask) {
  std::vector<unsigned> out;
  for (unsigned ch = 0; ch < 8; ++ch)
    if (mask & (1u << ch)) out.push_back(ch);
  return out;
}

// A register's value from its reply bytes.
constexpr auto word = lbp::read_le32;

}  // namespace

const ChannelSample* LiveStatus::channel(unsigned ch) const {
  const auto it =
      std::find_if(channels.begin(), channels.end(), [&](const auto& s) { return s.channel == ch; });
  return it == channels.end() ? nullptr : &*it;
}

// The one packet of every cycle, built once.
struct NormalModeSession::Cycle {
  std::vector<unsigned> channels;
  std::vector<lbp16::Command> packet;
};

void check_doit_period(std::chrono::milliseconds period) {
  if (period.count() <= 0 || period > kMaxDoitPeriod)
    throw UsageError("the DOIT period must be 1.." + std::to_string(kMaxDoitPeriod.count()) +
                     " ms to keep the 8I20's 40 ms watchdog fed");
}

NormalStart start_normal_mode(Lbp16Transport& bus, unsigned sserial_port, std::uint8_t mask,
                              const NormalModeOptions& options) {
  NormalStart out;
  const BoardIdentity card = identify(bus);
  out.hostmot2 = read_hostmot2(bus);
  const SserialPort port = find_sserial_port(out.hostmot2, sserial_port);
  out.port = std::make_unique<SslbpPort>(bus, port, card.has_timer_space(), options.sslbp);
  out.activity = require_no_running_host(bus, std::span(&port, 1), options.running_host,
                                         "stop and normal-start SSERIAL port " + std::to_string(port.index));
  out.port->stop_all();
  const std::uint8_t failed = out.port->start_normal(mask);
  const auto regs = out.port->read_channels(mask);
  const auto channels = channels_of(mask);
  std::string problems;
  for (std::size_t i = 0; i < channels.size(); ++i) {
    if (failed & (1u << channels[i])) {
      // Appended piece by piece: GCC 12's -Wrestrict misfires on `const char* + std::string`
      // chains in optimised builds.
      if (!problems.empty()) problems += "; ";
      problems += "ch " + std::to_string(channels[i]);
      problems += " (CS " + lbp::hex_value(regs[i].cs, 8) + ": " + regs[i].status().describe() + ")";
    }
    out.unit_numbers.emplace_back(channels[i], regs[i].interface0);
  }
  if (!problems.empty()) {
    try {
      out.port->stop_all();
    } catch (const Error&) {
      // The start failure is the news; a failing stop would only hide it.
    }
    throw DiscoveryError("normal start failed on " + out.port->describe() + ": " + problems);
  }
  return out;
}

std::unique_ptr<NormalModeSession> NormalModeSession::open(const EthTarget& target,
                                                           NormalModeOptions options) {
  return open(target.host_port, target.sserial_port, target.channel_mask(), options);
}

std::unique_ptr<NormalModeSession> NormalModeSession::open(const HostPort& host_port, unsigned sserial_port,
                                                           std::uint8_t channel_mask,
                                                           NormalModeOptions options) {
  auto bus = std::make_unique<UdpClient>(host_port.ip, host_port.port, options.udp);
  return std::make_unique<NormalModeSession>(std::move(bus), sserial_port, channel_mask, options);
}

NormalModeSession::NormalModeSession(std::unique_ptr<Lbp16Transport> bus, unsigned sserial_port,
                                     std::uint8_t channel_mask, NormalModeOptions options)
    : bus_(std::move(bus)), options_(options), mask_(channel_mask) {
  if (mask_ == 0) throw UsageError("a normal-mode session needs at least one channel");
  check_doit_period(options_.period);
  auto started = start_normal_mode(*bus_, sserial_port, mask_, options_);
  port_ = std::move(started.port);
  unit_numbers_ = std::move(started.unit_numbers);
  activity_ = started.activity;
  thread_ = std::thread([this] { worker(); });
}

NormalModeSession::~NormalModeSession() {
  try {
    stop();
  } catch (...) {
    // Destructors must not throw; stop() reports the same failure to callers that ask.
  }
}

std::string NormalModeSession::describe() const {
  std::string s = port_->describe() + " normal mode, ch";
  for (unsigned ch : channels_of(mask_)) {
    s += ' ';  // appended apart: GCC 12's -O3 -Wrestrict misfires on `" " + std::to_string(ch)`
    s += std::to_string(ch);
  }
  return s;
}

std::uint32_t NormalModeSession::unit_number(unsigned channel) const {
  for (const auto& [ch, unit] : unit_numbers_)
    if (ch == channel) return unit;
  throw UsageError("channel " + std::to_string(channel) + " is not part of " + describe());
}

void NormalModeSession::worker() {
  Cycle cycle;
  cycle.channels = channels_of(mask_);
  const auto& regs = port_->port().registers;
  cycle.packet.push_back(lbp16::read_hm2(regs.command));
  cycle.packet.push_back(lbp16::read_hm2(regs.data));
  for (unsigned ch : cycle.channels)
    for (std::uint16_t a : {regs.interface0(ch), regs.interface1(ch), regs.cs(ch)})
      cycle.packet.push_back(lbp16::read_hm2(a));
  for (unsigned ch : cycle.channels) cycle.packet.push_back(lbp16::write_hm2(regs.interface0(ch), 0u));
  cycle.packet.push_back(lbp16::write_hm2(regs.command, sslbp::doit(mask_)));

  std::uint64_t consecutive_missed = 0;
  auto next = Clock::now();
  std::unique_lock lock(mutex_);
  while (!stop_requested_) {
    lock.unlock();
    try {
      run_cycle(cycle, consecutive_missed);
    } catch (...) {
      fail(std::current_exception());
      return;
    }
    next += options_.period;
    if (next < Clock::now()) next = Clock::now();  // fell behind: do not burst to catch up
    lock.lock();
    changed_.wait_until(lock, next, [this] { return stop_requested_; });
  }
}

void NormalModeSession::run_cycle(const Cycle& cycle, std::uint64_t& consecutive_missed) {
  std::vector<lbp::Bytes> parts;
  try {
    parts = bus_->transact(cycle.packet, Resend::Never);
  } catch (const link::TimeoutError&) {
    ++missed_;
    if (++consecutive_missed >= options_.max_missed_cycles)
      throw link::TimeoutError(bus_->describe() + " stopped answering DOIT cycles (" +
                               std::to_string(consecutive_missed) +
                               " in a row); the 8I20 watchdog has likely bitten");
    return;
  }
  consecutive_missed = 0;
  const bool busy = (word(parts[0]) & 0xFFFF) != 0;
  if (busy) {
    ++late_;  // the previous DOIT had not finished: our DOIT write was not taken, data are in flux
    return;
  }
  const auto now = Clock::now();
  if (last_doit_)
    max_doit_gap_ =
        std::max(max_doit_gap_, std::chrono::duration_cast<std::chrono::microseconds>(now - *last_doit_));
  last_doit_ = now;
  const std::uint64_t previous_doits = doits_++;
  if (previous_doits == 0) return;  // before the first DOIT INTERFACE0 holds the unit number

  const auto data = static_cast<std::uint8_t>(word(parts[1]));
  LiveStatus status;
  status.taken = Clock::now();
  for (std::size_t i = 0; i < cycle.channels.size(); ++i) {
    const unsigned ch = cycle.channels[i];
    const std::uint32_t if0 = word(parts[2 + 3 * i]);
    const std::uint32_t if1 = word(parts[3 + 3 * i]);
    status.channels.push_back(ChannelSample{.channel = ch,
                                            .bus_voltage = static_cast<std::uint16_t>(if0 >> 16),
                                            .temperature = static_cast<std::uint16_t>(if0),
                                            .fault = static_cast<std::uint16_t>(if1 >> 16),
                                            .status = static_cast<std::uint16_t>(if1),
                                            .transfer_failed = (data & (1u << ch)) != 0,
                                            .cs = word(parts[4 + 3 * i])});
  }
  status.doits = doits_;
  status.late_cycles = late_;
  status.missed_cycles = missed_;
  status.max_doit_gap = max_doit_gap_;
  publish(std::move(status));
}

void NormalModeSession::publish(LiveStatus status) {
  {
    std::lock_guard lock(mutex_);
    status.sequence = latest_ ? latest_->sequence + 1 : 1;
    latest_ = std::move(status);
  }
  changed_.notify_all();
}

void NormalModeSession::fail(std::exception_ptr error) {
  {
    std::lock_guard lock(mutex_);
    error_ = error;
  }
  changed_.notify_all();
}

std::optional<LiveStatus> NormalModeSession::latest() const {
  std::lock_guard lock(mutex_);
  if (error_) std::rethrow_exception(error_);
  return latest_;
}

LiveStatus NormalModeSession::wait_for_sample(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  const bool ready = changed_.wait_for(lock, timeout, [this] {
    return error_ || stopped_ || (latest_ && latest_->sequence > returned_sequence_);
  });
  if (error_) std::rethrow_exception(error_);
  if (!ready || !latest_ || latest_->sequence <= returned_sequence_)
    throw link::TimeoutError("no live status from " + describe() + " within " +
                             std::to_string(timeout.count()) + " ms");
  returned_sequence_ = latest_->sequence;
  return *latest_;
}

bool NormalModeSession::running() const {
  std::lock_guard lock(mutex_);
  return !stopped_ && !stop_requested_ && !error_;
}

void NormalModeSession::stop() {
  {
    std::lock_guard lock(mutex_);
    if (stopped_) return;
    stop_requested_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
  {
    std::lock_guard lock(mutex_);
    stopped_ = true;
    // A sample the loop published before it stopped and nobody took goes with the session:
    // wait_for_sample() on a stopped session never returns one (it times out at once).
    if (latest_) returned_sequence_ = latest_->sequence;
  }
  changed_.notify_all();
  port_->wait_idle();  // the last DOIT may still be running; a stop written now would be ignored
  port_->stop_all();
}

}  // namespace i20::eth
