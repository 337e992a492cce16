// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/amplifier.hpp"

#include "sim/bits.hpp"
#include "sim/error.hpp"

namespace i20::sim {
namespace {

constexpr unsigned kDefaultBaudIndex = 9;  // 2.5 MBaud (manual, OPERATE MODE BAUD RATE)
constexpr unsigned kBaudIndexCount = 12;

}  // namespace

Amplifier::Amplifier(RegisterMap map, EepromStore eeprom, World world, AmplifierSettings settings)
    : map_(std::move(map)), eeprom_(std::move(eeprom)), world_(world), settings_(settings) {
  map_.validate();
}

void Amplifier::power_up(Clock::time_point now) {
  sticky_ = status::kExternalReset;
  load_working_from_nv();
  update(now);
}

void Amplifier::reset(Clock::time_point now, std::uint16_t sticky_cause) {
  sticky_ |= sticky_cause;
  load_working_from_nv();
  update(now);
}

void Amplifier::load_working_from_nv() {
  std::fill(ram_.begin(), ram_.end(), 0);
  for (const auto& r : map_.all()) {
    if (r.space != Space::Ram) continue;
    const Register* nv = r.twin.empty() ? nullptr : map_.find(r.twin);
    if (nv && nv->space == Space::Eeprom)
      write_raw(r, read_raw(*nv));
    else if (r.default_value)
      write_raw(r, static_cast<std::uint64_t>(*r.default_value));
  }
  write_raw(map_.at("SWREVISION"), map_.swrevision());
  write_raw(map_.at("UNITNUMBER"), settings_.unit_number);
  const auto* baud = map_.find("NVBAUDRATE");
  baud_index_ = baud ? static_cast<unsigned>(read_raw(*baud)) : kDefaultBaudIndex;
  if (baud_index_ >= kBaudIndexCount) baud_index_ = kDefaultBaudIndex;
  latched_faults_ = 0;
  brake_on_ = false;
  last_valid_command_.reset();
  watchdog_set_ = false;
  clear_due_.reset();
}

void Amplifier::update(Clock::time_point now) {
  const auto sample = world_.sample();
  last_temperature_c_ = sample.temperature_c;
  write_raw(map_.at("BUSV"), sample.busv_raw);
  write_raw(map_.at("TEMPERATURE"), sample.temperature_raw);
  update_brake(sample.bus_volts);
  const std::uint16_t present = causes(sample, now);
  if ((present & ~previous_causes_) & fault::kWatchdog) ++watchdog_bites_;
  previous_causes_ = present;
  latched_faults_ |= present;
  handle_clearfault(now, present);
  write_raw(map_.at("FAULT"), latched_faults_);
  write_raw(map_.at("STATUS"), status());
}

void Amplifier::feed_watchdog(Clock::time_point now) {
  last_valid_command_ = now;
}

bool Amplifier::watchdog_running() const {
  return settings_.operate_mode && last_valid_command_ && (!settings_.watchdog_set_by_host || watchdog_set_);
}

std::optional<Clock::time_point> Amplifier::watchdog_due() const {
  if (!watchdog_running() || (previous_causes_ & fault::kWatchdog)) return std::nullopt;
  return *last_valid_command_ + settings_.watchdog + Duration(1);
}

std::uint16_t Amplifier::causes(const World::Sample& s, Clock::time_point now) const {
  const auto& w = world_.settings();
  std::uint16_t c = w.forced_faults & fault::kDefined;
  if (!w.enable) c |= fault::kNoEnable;
  if (s.temperature_c > kOverTempC) c |= fault::kOverTemp;
  if (s.busv_raw < ram16("BUSUNDERV")) c |= fault::kBusLow;
  if (s.busv_raw > ram16("BUSOVERV")) c |= fault::kBusHigh;
  if (s.bus_volts > kFixedOverVolts) c |= fault::kBusMax;
  if (watchdog_running() && now - *last_valid_command_ > settings_.watchdog) c |= fault::kWatchdog;
  return c;
}

void Amplifier::update_brake(double bus_volts) {
  const double on_v = ram16("BRAKEONV") * 0.01;
  const double off_v = ram16("BRAKEOFFV") * 0.01;
  if (bus_volts > on_v || bus_volts > kFixedBrakeOnVolts)
    brake_on_ = true;
  else if (bus_volts < off_v)
    brake_on_ = false;
  if (brake_on_) sticky_ |= status::kBrakeWasOn;
}

void Amplifier::handle_clearfault(Clock::time_point now, std::uint16_t present) {
  if (ram16("CLEARFAULT") == 0) {
    clear_due_.reset();
    return;
  }
  if (!clear_due_) clear_due_ = now + settings_.clearfault_delay;
  if (clearfault_stuck_ || now < *clear_due_) return;
  latched_faults_ = present;  // bits whose cause is gone drop out
  sticky_ = brake_on_ ? status::kBrakeWasOn : 0;
  write_raw(map_.at("CLEARFAULT"), 0);
  clear_due_.reset();
}

std::uint16_t Amplifier::status() const {
  const auto& w = world_.settings();
  std::uint16_t s = sticky_;
  if (brake_on_) s |= status::kBrakeOn;
  if (last_temperature_c_ > kCurrentLimitC) s |= status::kCurrentLimited;
  if (ram16("BUSV") < ram16("BUSUNDERV")) s |= status::kBusUnderV;
  if (!w.enable) s |= status::kNoEnable;
  if (settings_.operate_mode && w.enable && !fault_output_active()) s |= status::kCurrentLoopOn;
  return s;
}

bool Amplifier::fault_output_active() const {
  const std::uint16_t mask = ram16("FAULTMASK") | static_cast<std::uint16_t>(~fault::kMaskable);
  return (latched_faults_ & mask) != 0;
}

bool Amplifier::ram_write_protected(std::uint16_t address, std::size_t length) const {
  for (const auto& r : map_.all()) {
    if (r.space != Space::Ram || !r.read_only) continue;
    // Wrap-around at 0xFFFF is checked byte by byte.
    for (std::size_t i = 0; i < length; ++i)
      if (r.overlaps(static_cast<std::uint16_t>(address + i), 1)) return true;
  }
  return false;
}

void Amplifier::write_ram(std::uint16_t address, lbp::ByteView data) {
  for (std::size_t i = 0; i < data.size(); ++i) ram_[static_cast<std::uint16_t>(address + i)] = data[i];
}

std::uint64_t Amplifier::value(std::string_view name) const {
  return read_raw(map_.at(name));
}

void Amplifier::poke(std::string_view name, std::uint64_t value) {
  const auto& r = map_.at(name);
  if (r.space == Space::Eeprom) {
    eeprom_.write(r.address, lbp::to_le(value, r.bytes()));
    return;
  }
  write_raw(r, value);
}

std::uint64_t Amplifier::read_raw(const Register& r) const {
  std::uint64_t v = 0;
  for (unsigned i = r.bytes(); i-- > 0;) {
    const std::size_t a = r.address + i;
    const lbp::Byte b =
        r.space == Space::Ram ? ram_[a & 0xFFFF] : (a < eeprom_.size() ? eeprom_.at(a) : 0xFF);
    v = (v << 8) | b;
  }
  return v;
}

void Amplifier::write_raw(const Register& r, std::uint64_t value) {
  if (r.space == Space::Eeprom)
    throw ConfigError("internal: " + r.name + " is an EEPROM parameter and is written through the EEPROM");
  for (unsigned i = 0; i < r.bytes(); ++i)
    ram_[static_cast<std::uint16_t>(r.address + i)] = static_cast<lbp::Byte>(value >> (8 * i));
}

std::uint16_t Amplifier::ram16(std::string_view name) const {
  return static_cast<std::uint16_t>(read_raw(map_.at(name)));
}

}  // namespace i20::sim
