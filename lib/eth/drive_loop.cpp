// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/drive_loop.hpp"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cstdio>
#include <thread>

#include "eth/errors.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace hm2 = lbp::hm2;
namespace sslbp = lbp::hm2::sslbp;
using Clock = std::chrono::steady_clock;

namespace {

// A register's value from its reply bytes.
constexpr auto word = lbp::read_le32;

std::string padded(unsigned value, int digits) {
  char text[16];
  std::snprintf(text, sizeof text, "%0*u", digits, value);
  return text;
}

// Arms one index event (hostmot2's own way: LatchOnIndex with JustOnce, falling edge).
constexpr std::uint32_t kArmIndex = hm2::encoder_bit::kLatchOnIndex | hm2::encoder_bit::kJustOnce;
// Space 4's uSTimeStamp register: "the free running hardware microsecond timer" (7I92T and
// 7I96S manuals, SPACE 4 LBP TIMER/UTILITY AREA), 16 bits.
constexpr std::uint16_t kMicrosecondTimerAddress = 0x0000;

}  // namespace

FeedbackMap feedback_map(const HostMot2Info& info) {
  FeedbackMap map;
  if (const auto* enc = info.find(hm2::gtag::kEncoder))
    for (unsigned i = 0; i < enc->instances; ++i)
      map.encoders.push_back(
          {.instance = i,
           .count = enc->register_address(info.idrom, hm2::encoder_reg::kCount, i),
           .latch_control = enc->register_address(info.idrom, hm2::encoder_reg::kLatchControl, i)});
  const unsigned width = info.idrom.port_width;
  if (const auto* io = info.find(hm2::gtag::kIoPort); io && width > 0) {
    const std::size_t first = map.input_words.size();
    for (unsigned i = 0; i < io->instances; ++i)
      map.input_words.push_back(io->register_address(info.idrom, hm2::ioport_reg::kData, i));
    for (unsigned pin = 0; pin < info.pins.size() && pin / width < io->instances; ++pin)
      if (info.pins[pin].secondary_tag == 0) {
        std::string name = "gpio.";
        name += padded(pin, 3);
        name += ".in";
        map.inputs.push_back({.word = first + pin / width, .bit = pin % width, .hal_pin = name});
      }
  }
  if (const auto* inm = info.find(hm2::gtag::kInm)) {
    const std::size_t w = map.input_words.size();
    map.input_words.push_back(inm->register_address(info.idrom, hm2::inm_reg::kFilteredData, 0));
    map.inm_word = w;
    map.inm_control = inm->register_address(info.idrom, hm2::inm_reg::kControl, 0);
    for (const auto& pin : info.pins)
      // Secondary pin numbers count from 1 (as an encoder's A, B, index are 1, 2, 3).
      if (pin.secondary_tag == hm2::gtag::kInm && pin.secondary_unit == 0 &&
          (pin.secondary_pin & 0x7F) >= 1) {
        const unsigned input = (pin.secondary_pin & 0x7Fu) - 1;
        std::string name = "inm.00.input-";
        name += padded(input, 2);
        map.inputs.push_back({.word = w, .bit = input, .hal_pin = name});
      }
  }
  return map;
}

std::chrono::microseconds DoitStats::percentile(double p) const {
  if (gaps.empty()) return std::chrono::microseconds{0};
  auto sorted = gaps;
  std::sort(sorted.begin(), sorted.end());
  const auto index = static_cast<std::size_t>(p / 100.0 * static_cast<double>(sorted.size() - 1) + 0.5);
  return sorted[std::min(index, sorted.size() - 1)];
}

std::chrono::microseconds DoitStats::worst() const {
  return gaps.empty() ? std::chrono::microseconds{0} : *std::max_element(gaps.begin(), gaps.end());
}

std::unique_ptr<DriveLoop> DriveLoop::open(const EthTarget& target, NormalModeOptions options) {
  auto bus = std::make_unique<UdpClient>(target.host_port.ip, target.host_port.port, options.udp);
  return std::make_unique<DriveLoop>(std::move(bus), target.sserial_port, target.channel, options);
}

DriveLoop::DriveLoop(std::unique_ptr<Lbp16Transport> bus, unsigned sserial_port, unsigned channel,
                     NormalModeOptions options)
    : bus_(std::move(bus)), options_(options), channel_(channel) {
  if (channel_ >= 8) throw UsageError("an SSERIAL channel is 0..7");
  check_doit_period(options_.period);
  auto started = start_normal_mode(*bus_, sserial_port, static_cast<std::uint8_t>(1u << channel_), options_);
  hostmot2_ = std::move(started.hostmot2);
  port_ = std::move(started.port);
  activity_ = started.activity;
  unit_number_ = started.unit_numbers.front().second;
  map_ = feedback_map(hostmot2_);
  next_ = Clock::now();
}

DriveLoop::~DriveLoop() {
  try {
    stop();
  } catch (...) {
    // Destructors must not throw; the 8I20's watchdog disables the output without DOITs.
  }
}

std::string DriveLoop::describe() const {
  std::string s = port_->describe();
  s += " ch ";
  s += std::to_string(channel_);
  return s;
}

std::vector<lbp16::Command> DriveLoop::packet(DriveSetpoint setpoint) const {
  const auto& regs = port_->port().registers;
  std::vector<lbp16::Command> p;
  p.push_back(lbp16::read_hm2(regs.command));
  p.push_back(lbp16::read_hm2(regs.data));
  p.push_back(lbp16::read_hm2(regs.interface0(channel_)));
  p.push_back(lbp16::read_hm2(regs.interface1(channel_)));
  // The card's own time of the readings below (DriveReading::card_microseconds).
  p.push_back(lbp16::read(lbp16::space::kTimers, kMicrosecondTimerAddress, lbp16::Width::Bits16));
  for (const auto& e : map_.encoders) {
    p.push_back(lbp16::read_hm2(e.count));
    p.push_back(lbp16::read_hm2(e.latch_control));
  }
  for (const auto address : map_.input_words) p.push_back(lbp16::read_hm2(address));
  if (map_.inm_word) p.push_back(lbp16::read_hm2(map_.inm_control));
  const std::uint32_t if0 =
      static_cast<std::uint32_t>(static_cast<std::uint16_t>(setpoint.qsetpoint)) << 16 | setpoint.angle;
  p.push_back(lbp16::write_hm2(regs.interface0(channel_), if0));
  for (const auto& e : map_.encoders) p.push_back(lbp16::write_hm2(e.latch_control, kArmIndex));
  p.push_back(lbp16::write_hm2(regs.command, sslbp::doit(static_cast<std::uint8_t>(1u << channel_))));
  return p;
}

DriveReading DriveLoop::decode(const std::vector<lbp::Bytes>& parts) {
  DriveReading r;
  r.taken = Clock::now();
  r.fresh = (word(parts[0]) & 0xFFFF) == 0;
  r.command_taken = r.fresh;  // the packet writes its DOIT after this read
  r.transfer_failed = (word(parts[1]) & (1u << channel_)) != 0;
  const std::uint32_t if0 = word(parts[2]), if1 = word(parts[3]);
  r.bus_voltage = static_cast<std::uint16_t>(if0 >> 16);
  r.fault = static_cast<std::uint16_t>(if1 >> 16);
  r.status = static_cast<std::uint16_t>(if1);
  r.card_microseconds = static_cast<std::uint16_t>(lbp::read_le(parts[4]));
  std::size_t i = 5;
  for (std::size_t e = 0; e < map_.encoders.size(); ++e) {
    EncoderReading reading;
    reading.count = static_cast<std::uint16_t>(word(parts[i++]));
    reading.latch_control = word(parts[i++]);
    // LatchOnIndex reads 0 once the armed event happened (JustOnce cleared it).
    reading.index_latched = latches_armed_ && !(reading.latch_control & hm2::encoder_bit::kLatchOnIndex);
    reading.latched = static_cast<std::uint16_t>(reading.latch_control >> 16);
    r.encoders.push_back(reading);
  }
  for (std::size_t w = 0; w < map_.input_words.size(); ++w) r.input_words.push_back(word(parts[i++]));
  if (map_.inm_word && !(word(parts[i++]) & hm2::inm_reg::kGlobalInvert))
    r.input_words[*map_.inm_word] = ~r.input_words[*map_.inm_word];
  return r;
}

DriveReading DriveLoop::cycle(DriveSetpoint setpoint) {
  if (stopped_) throw UsageError(describe() + " is stopped");
  next_ += options_.period;
  const auto now = Clock::now();
  if (next_ > now)
    std::this_thread::sleep_until(next_);
  else
    next_ = now;  // fell behind: do not burst to catch up
  const auto commands = packet(setpoint);
  std::vector<lbp::Bytes> parts;
  const auto sent = Clock::now();
  try {
    parts = bus_->transact(commands, Resend::Never);
  } catch (const link::TimeoutError&) {
    ++stats_.missed;
    if (++consecutive_missed_ >= options_.max_missed_cycles)
      throw link::TimeoutError(bus_->describe() + " stopped answering DOIT cycles (" +
                               std::to_string(consecutive_missed_) +
                               " in a row); the 8I20 watchdog has likely bitten");
    DriveReading lost;
    lost.taken = Clock::now();
    lost.sent = sent;
    lost.fresh = false;
    lost.command_taken = false;  // unknown: the request may have arrived; the caller sends it again
    return lost;
  }
  consecutive_missed_ = 0;
  DriveReading reading = decode(parts);
  reading.sent = sent;
  latches_armed_ = true;
  if (!reading.fresh) {
    ++stats_.late;
    return reading;
  }
  if (stats_.doits++ == 0) {
    // Before the first DOIT completes, INTERFACE0/1 still hold the unit number and the
    // card name, not bus voltage and FAULT.
    reading.fresh = false;
    reading.bus_voltage = reading.fault = reading.status = 0;
  }
  if (last_doit_)
    stats_.gaps.push_back(std::chrono::duration_cast<std::chrono::microseconds>(reading.taken - *last_doit_));
  last_doit_ = reading.taken;
  return reading;
}

std::uint32_t DriveLoop::foreign_packets() {
  return foreign_packets_since(*bus_, activity_, options_.running_host);
}

void DriveLoop::stop() {
  if (stopped_) return;
  std::exception_ptr failure;
  for (unsigned i = 0; i < options_.zero_cycles_before_stop; ++i) try {
      cycle(DriveSetpoint{});
    } catch (...) {
      failure = std::current_exception();
      break;
    }
  stopped_ = true;
  port_->wait_idle();  // the last DOIT may still be running; a stop written now would be ignored
  port_->stop_all();
  if (failure) std::rethrow_exception(failure);
}

RealtimePriority::RealtimePriority() {
  sched_param old{};
  if (pthread_getschedparam(pthread_self(), &old_policy_, &old) != 0) return;
  old_priority_ = old.sched_priority;
  sched_param fifo{};
  fifo.sched_priority = 10;
  granted_ = pthread_setschedparam(pthread_self(), SCHED_FIFO, &fifo) == 0;
}

RealtimePriority::~RealtimePriority() {
  if (!granted_) return;
  sched_param old{};
  old.sched_priority = old_priority_;
  pthread_setschedparam(pthread_self(), old_policy_, &old);
}

}  // namespace i20::eth
