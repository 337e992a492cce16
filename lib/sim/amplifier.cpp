// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/amplifier.hpp"

#include <cmath>
#include <numbers>

#include "motor/amp_gains.hpp"
#include "sim/bits.hpp"
#include "sim/error.hpp"

namespace i20::sim {
namespace {

constexpr unsigned kDefaultBaudIndex = 9;  // 2.5 MBaud (manual, OPERATE MODE BAUD RATE)
constexpr unsigned kBaudIndexCount = 12;

// The 8I20 puts the current vector a quarter electrical turn ahead of ANGLE for positive
// QSETPOINT (behind it for negative): an inference from LinuxCNC feeding bldc's rotor-angle,
// without lead, to the card (docs/motor-model.md). In the card's ANGLE frame that is a
// current on the q axis only.
constexpr double kLeadRad = std::numbers::pi / 2;
// "U current >125% of MAXCURRENT" (manual, FAULT CONDITIONS).
constexpr double kPhaseTripFraction = 1.25;
constexpr std::uint16_t kPhaseFaults[3] = {fault::kULoop, fault::kVLoop, fault::kWLoop};
// A runaway's energy comes back into the bus: the settable over-voltage fault trips first.
constexpr std::uint16_t kRunawayFault = fault::kBusHigh;

double seconds(Duration d) {
  return std::chrono::duration<double>(d).count();
}

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
  run_motor(now);
  const auto sample = world_.sample();
  last_temperature_c_ = sample.temperature_c;
  last_bus_volts_ = sample.bus_volts;
  write_raw(map_.at("BUSV"), sample.busv_raw);
  write_raw(map_.at("TEMPERATURE"), sample.temperature_raw);
  update_brake(sample.bus_volts);
  const std::uint16_t present = causes(sample, now) | take_motor_causes();
  if ((present & ~previous_causes_) & fault::kWatchdog) ++watchdog_bites_;
  previous_causes_ = present;
  latched_faults_ |= present;
  handle_clearfault(now, present);
  write_raw(map_.at("FAULT"), latched_faults_);
  write_raw(map_.at("STATUS"), status());
  command_motor();
}

void Amplifier::attach_motor(const motor::MotorParams& params, Clock::time_point now) {
  motor_.emplace(params);
  motor_time_ = now;
  motor_attached_ = now;
  motor_causes_ = 0;
  command_motor();
}

std::optional<double> Amplifier::motor_turns_at(Clock::time_point t) const {
  if (!motor_) return std::nullopt;
  const auto& s = motor_->state();
  // The state holds at the end of its last whole PWM period, not at motor_time_ (which
  // carries the part period not yet run).
  const double since_state = seconds(t - motor_attached_) - s.time_s;
  return s.angle_turns + s.speed_rad_s / (2.0 * std::numbers::pi) * since_state;
}

void Amplifier::set_motor_params(const motor::MotorParams& params, Clock::time_point now) {
  if (!motor_) return;
  run_motor(now);
  motor_->set_params(params);
}

void Amplifier::set_motor_sensor_faults(motor::SensorFaults faults, Clock::time_point now) {
  if (!motor_) return;
  run_motor(now);
  motor_->set_sensor_faults(faults);
}

void Amplifier::bridge_off(Clock::time_point now) {
  if (!motor_) return;
  run_motor(now);
  auto off = motor_->drive();
  off.output_on = false;
  motor_->command(off);
}

void Amplifier::step_motor_to(Clock::time_point t) {
  if (t <= motor_time_) return;
  motor_->step(seconds(t - motor_time_));
  motor_time_ = t;
}

void Amplifier::run_motor(Clock::time_point now) {
  if (!motor_ || now <= motor_time_) return;
  // A watchdog that bites within this stretch switches the bridge off when it bites, not
  // when the next command or tick notices it.
  if (const auto due = watchdog_due(); due && *due > motor_time_ && *due < now && motor_->drive().output_on) {
    step_motor_to(*due);
    bridge_off(*due);
  }
  step_motor_to(now);
  const unsigned phases = motor_->take_overcurrent();
  for (unsigned k = 0; k < 3; ++k)
    if (phases & (1u << k)) motor_causes_ |= kPhaseFaults[k];
  const auto& max_speed = motor_->params().max_speed_rad_s;
  if (motor_->take_runaway() || (max_speed && std::abs(motor_->state().speed_rad_s) > *max_speed))
    motor_causes_ |= kRunawayFault;
}

std::uint16_t Amplifier::take_motor_causes() {
  const std::uint16_t c = motor_causes_;
  motor_causes_ = 0;
  return c;
}

// The drive the card's registers ask for now: on while the current loop is (STATUS bit 9).
void Amplifier::command_motor() {
  if (!motor_) return;
  motor::DriveCommand d = motor_->drive();
  const auto angle = ram_value("ANGLE"), setpoint = ram_value("QSETPOINT"), max_raw = ram_value("MAXCURRENT");
  const auto kqp = ram_value("KQP"), kqi = ram_value("KQI"), kdp = ram_value("KDP"), kdi = ram_value("KDI");
  const double max_current = max_raw ? static_cast<double>(*max_raw) * 0.01 : 0;
  d.output_on = (status() & status::kCurrentLoopOn) && angle && setpoint && kqp && kqi && kdp && kdi &&
                max_current > 0 && last_bus_volts_ > 0;
  if (d.output_on) {
    const double command = static_cast<std::int16_t>(*setpoint) / 32767.0 * max_current;
    d.frame_angle_rad = static_cast<double>(*angle) * (2 * std::numbers::pi / 65536.0);
    d.current_a = {command * std::cos(kLeadRad), command * std::sin(kLeadRad)};
    d.q_gains = motor::physical_gains(static_cast<std::int64_t>(*kqp), static_cast<std::int64_t>(*kqi),
                                      max_current, last_bus_volts_);
    d.d_gains = motor::physical_gains(static_cast<std::int64_t>(*kdp), static_cast<std::int64_t>(*kdi),
                                      max_current, last_bus_volts_);
    d.bus_voltage_v = last_bus_volts_;
    d.phase_trip_a = kPhaseTripFraction * max_current;
  }
  motor_->command(d);
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
  command_motor();  // a new ANGLE, QSETPOINT or gain takes effect from now
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
  command_motor();
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

std::optional<std::uint64_t> Amplifier::ram_value(std::string_view name) const {
  const Register* r = map_.find(name);
  if (!r || r->space != Space::Ram) return std::nullopt;
  return read_raw(*r);
}

std::uint16_t Amplifier::ram16(std::string_view name) const {
  return static_cast<std::uint16_t>(read_raw(map_.at(name)));
}

}  // namespace i20::sim
