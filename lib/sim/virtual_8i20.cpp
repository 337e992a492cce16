// SPDX-License-Identifier: GPL-2.0-or-later
// Time, framing and reply handling of the virtual 8I20. Command semantics live in
// lbp_commands.cpp.
#include "sim/virtual_8i20.hpp"

#include <algorithm>

#include "lbp/crc8.hpp"
#include "sim/bits.hpp"
#include "sim/rpc_table.hpp"

namespace i20::sim {
namespace {

// NVBAUDRATE index -> bits per second (manual, OPERATE MODE BAUD RATE).
constexpr unsigned kOperateBauds[] = {9600,   19200,  38400,   57600,   115200,  230400,
                                      460800, 921600, 1250000, 2500000, 5000000, 10000000};

EepromStore make_eeprom(const DeviceOptions& o) {
  if (o.eeprom_file) return EepromStore(o.map, o.eeprom_bytes, *o.eeprom_file);
  return EepromStore(o.map, o.eeprom_bytes);
}

AmplifierSettings amplifier_settings(const DeviceOptions& o) {
  AmplifierSettings s = o.amplifier;
  s.operate_mode = o.mode == FramingMode::Operate;
  return s;
}

}  // namespace

Virtual8i20::Virtual8i20(DeviceOptions options, Clock::time_point power_on)
    : options_(std::move(options)),
      amplifier_(options_.map, make_eeprom(options_), World(options_.world), amplifier_settings(options_)),
      framer_({options_.mode, options_.rx_buffer_bytes, {}}),
      injection_(options_.injection),
      rng_(options_.injection.seed),
      now_(power_on) {
  amplifier_.set_clearfault_stuck(injection_.clearfault_stuck);
  amplifier_.power_up(power_on);
  if (options_.motor) amplifier_.attach_motor(*options_.motor, power_on);
  start_lbp(power_on);
}

void Virtual8i20::start_lbp(Clock::time_point t) {
  lbp_ = LbpRegisters{};
  lbp_.command_timeout = options_.command_timeout;
  rpc_table_ = preloaded_rpc_table(amplifier_.map());
  framer_.clear();
  busy_until_.reset();
  eeprom_pending_.clear();
  watchdog_bites_seen_ = amplifier_.watchdog_bites();
  apply_command_timeout();
  now_ = std::max(now_, t);
}

unsigned Virtual8i20::baud() const {
  if (options_.mode == FramingMode::Setup) return kSetupBaud;
  return kOperateBauds[std::min<std::size_t>(amplifier_.baud_index(), std::size(kOperateBauds) - 1)];
}

Clock::duration Virtual8i20::character_time() const {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(10.0 / baud()));
}

void Virtual8i20::apply_command_timeout() {
  // The register counts tenths of character times (manual: 0xCB "character times/10").
  const unsigned tenths = std::max<unsigned>(lbp_.command_timeout, 1);
  framer_.set_timeout(character_time() * tenths / 10);
}

bool Virtual8i20::deaf(Clock::time_point t) const {
  return !powered_ || (deaf_until_ && t < *deaf_until_);
}

void Virtual8i20::receive(lbp::ByteView bytes, Clock::time_point now) {
  now = std::max(now, now_);
  for (lbp::Byte b : bytes) {
    ++stats_.bytes_received;
    service(now);
    if (deaf(now)) {
      ++stats_.bytes_ignored;
      continue;
    }
    framer_.push(b, now);
    service(now);
  }
  if (bytes.empty()) service(now);
}

void Virtual8i20::advance(Clock::time_point now) {
  service(std::max(now, now_));
}

void Virtual8i20::service(Clock::time_point now) {
  now_ = std::max(now_, now);
  if (!powered_) {
    amplifier_.run_motor(now_);  // the rotor turns on without the card
    return;
  }
  amplifier_.set_clearfault_stuck(injection_.clearfault_stuck);
  if (deaf_until_ && now_ >= *deaf_until_) deaf_until_.reset();
  Clock::time_point cursor = now_;
  bool expired = false;
  for (;;) {
    if (busy_until_) {
      if (now_ < *busy_until_) break;
      cursor = *busy_until_;
      finish_eeprom_write();
      if (!powered_) return;
    }
    if (deaf(cursor)) break;
    auto frame = framer_.next(rpc_table_);
    if (!frame) {
      // Nothing ready: the quiet-line rules may drop a partial command (setup mode) or
      // close a packet (operate mode), once per pass.
      if (busy_until_ || expired) break;
      framer_.expire(now_);
      expired = true;
      continue;
    }
    execute(*frame, cursor);
    if (!powered_) return;
  }
  // A reset in this pass (reset_time zero, or one that began at an earlier cursor) may
  // already be over: its end is not an event still to come.
  if (deaf_until_ && now_ >= *deaf_until_) deaf_until_.reset();
  note_framer_events();
  amplifier_.update(std::max(cursor, now_));
}

void Virtual8i20::note_framer_events() {
  if (framer_.take_overflow()) {
    lbp_.status |= lbp::local::kStatusBufferOverflow;
    trace("receive buffer overflow: bytes dropped");
  }
  if (framer_.take_timeout()) {
    lbp_.status |= lbp::local::kStatusCommandTimeout;
    trace("command timeout: partial command or garbage dropped");
  }
}

void Virtual8i20::execute(const Framer::Frame& frame, Clock::time_point t) {
  if (muted()) {
    ++stats_.commands_ignored;
    return;
  }
  if (!frame.crc_ok) {
    lbp_.crc_errors = static_cast<lbp::Byte>(std::min(lbp_.crc_errors + 1, 255));
    lbp_.status |= lbp::local::kStatusCrcError;
    ++stats_.bad_crc;
    trace("bad CRC, not executed: " + lbp::to_hex(frame.command));
    return;
  }
  amplifier_.update(t);  // a watchdog that bit before this command is seen first
  if (amplifier_.watchdog_bites() != watchdog_bites_seen_) {
    watchdog_bites_seen_ = amplifier_.watchdog_bites();
    lbp_.status |= lbp::local::kStatusWatchdog;
  }
  amplifier_.feed_watchdog(t);
  bool reset_requested = false;
  const lbp::Bytes reply = dispatch(frame.command, t, reset_requested);
  ++stats_.commands_executed;
  if (!powered_) return;  // power failed during an EEPROM write: no reply, nothing more
  emit(reply, busy_until_.value_or(t));
  trace(lbp::to_hex(frame.command) + " -> " + lbp::to_hex(reply));
  if (reset_requested) reset_processor(t, status::kSoftwareReset);
  after_command(t);
}

void Virtual8i20::after_command(Clock::time_point t) {
  if (injection_.answer_limit && *injection_.answer_limit > 0) --*injection_.answer_limit;
  if (injection_.reset_after_commands) {
    if (*injection_.reset_after_commands > 0) --*injection_.reset_after_commands;
    if (*injection_.reset_after_commands == 0) {
      injection_.reset_after_commands.reset();
      trace("injected reset (DSP watchdog)");
      reset_processor(t, status::kDspWatchdogReset);
    }
  }
}

void Virtual8i20::reset_processor(Clock::time_point t, std::uint16_t sticky_cause) {
  ++stats_.resets;
  stats_.bytes_received_at_reset = stats_.bytes_received;
  amplifier_.reset(t, sticky_cause);
  start_lbp(t);
  deaf_until_ = t + options_.reset_time;
}

void Virtual8i20::finish_eeprom_write() {
  for (const auto& w : eeprom_pending_) amplifier_.eeprom().write(w.offset, w.data);
  eeprom_pending_.clear();
  busy_until_.reset();
}

double Virtual8i20::roll() {
  return static_cast<double>(rng_() >> 11) * 0x1.0p-53;
}

void Virtual8i20::emit(const lbp::Bytes& data, Clock::time_point t) {
  if (injection_.drop_rate > 0 && roll() < injection_.drop_rate) {
    ++stats_.replies_dropped;
    trace("reply dropped (injected)");
    return;
  }
  lbp::Bytes wire = data;
  wire.push_back(lbp::crc8(data));
  if (injection_.corrupt_rate > 0)
    for (auto& b : wire)
      if (roll() < injection_.corrupt_rate) b ^= static_cast<lbp::Byte>(1u << (rng_() % 8));
  outbox_.push_back({t + injection_.reply_delay, std::move(wire)});
}

lbp::Bytes Virtual8i20::take_output() {
  lbp::Bytes out;
  while (!outbox_.empty() && outbox_.front().release <= now_) {
    const auto& o = outbox_.front().bytes;
    out.insert(out.end(), o.begin(), o.end());
    outbox_.pop_front();
  }
  return out;
}

std::optional<Clock::time_point> Virtual8i20::next_event() const {
  std::optional<Clock::time_point> next;
  const auto consider = [&](std::optional<Clock::time_point> t) {
    if (t && (!next || *t < *next)) next = t;
  };
  if (!powered_) return std::nullopt;
  consider(busy_until_);
  consider(deaf_until_);
  if (!busy_until_) consider(framer_.deadline());  // quiet-line rules wait for the EEPROM
  if (!outbox_.empty() && outbox_.front().release > now_) consider(outbox_.front().release);
  consider(amplifier_.clearfault_due());
  consider(amplifier_.watchdog_due());
  return next;
}

void Virtual8i20::power_off() {
  powered_ = false;
  amplifier_.bridge_off(now_);
  framer_.clear();
  outbox_.erase(
      std::remove_if(outbox_.begin(), outbox_.end(), [&](const Outgoing& o) { return o.release > now_; }),
      outbox_.end());
  busy_until_.reset();
  eeprom_pending_.clear();
  deaf_until_.reset();
  trace("power off");
}

void Virtual8i20::power_cycle(Clock::time_point now) {
  now_ = std::max(now_, now);
  power_off();
  powered_ = true;
  // A power-up is a processor start like any reset (the ground truth counts it: the working
  // values it reloads are the card's doing).
  ++stats_.resets;
  stats_.bytes_received_at_reset = stats_.bytes_received;
  amplifier_.power_up(now_);
  start_lbp(now_);
  trace("power on");
}

void Virtual8i20::set_injection(const Injection& injection) {
  injection_ = injection;
  rng_.seed(injection.seed);
  amplifier_.set_clearfault_stuck(injection.clearfault_stuck);
}

}  // namespace i20::sim
