// SPDX-License-Identifier: GPL-2.0-or-later
// The amplifier behind the LBP interface: working parameters in RAM, NV parameters in
// EEPROM, and the FAULT / STATUS / brake logic driven by the simulated world
// (manual "DRIVE PARAMETER SETUP", "FAULT CONDITIONS", "STATUS REGISTER", "MOTOR BRAKE").
//
// Rules modelled:
//  - power-up and reset copy every NV value into its working twin; NV writes change
//    nothing live.
//  - FAULT bits latch while their cause is present and are cleared only by CLEARFAULT:
//    the host writes non-zero, and after `clearfault_delay` the card clears the bits whose
//    cause is gone, clears the sticky STATUS bits (the manual's "or the status register
//    is cleared"; this is the simulator's reading) and sets CLEARFAULT back to 0.
//  - FAULTMASK: a 0 bit masks that fault from the fault output; only bit 8 is maskable.
//  - Brake: on above BRAKEONV or the fixed 385 V, off below BRAKEOFFV (hysteresis).
//  - STATUS bit 0 (current limited) is set above 70 C (the card's 70 C derating point);
//    bits 3, 8 and 9 follow LinuxCNC's names (docs/facts.md s4).
//  - With a motor attached (attach_motor), the current loop drives it while it is on (operate
//    mode, enable driven, no unmasked fault: STATUS bit 9): QSETPOINT/32767 x MAXCURRENT at
//    ANGLE plus the card's lead (+90 electrical degrees for positive current, an inference:
//    docs/motor-model.md), with the working KQP/KQI, KDP/KDI and the measured bus. A phase
//    above 125% of MAXCURRENT latches that phase's loop-current fault (bits 5-7); a speed
//    beyond the motor's max_speed latches BUSHIVFAULT (bit 9), what a runaway's regenerated
//    energy shows on a real card. The motor advances on the simulator's clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>

#include "lbp/bytes.hpp"
#include "motor/motor.hpp"
#include "sim/eeprom_store.hpp"
#include "sim/register_map.hpp"
#include "sim/world.hpp"

namespace i20::sim {

using Clock = std::chrono::steady_clock;
using Duration = Clock::duration;

inline constexpr double kFixedBrakeOnVolts = 385.0;
inline constexpr double kFixedOverVolts = 400.0;
inline constexpr double kOverTempC = 85.0;
inline constexpr double kCurrentLimitC = 70.0;

struct AmplifierSettings {
  std::uint32_t unit_number = 0x00012345;
  Duration clearfault_delay = std::chrono::milliseconds(5);
  Duration watchdog = std::chrono::milliseconds(40);  // SSLBP sets 40 ms (manual, SSLBP)
  bool operate_mode = false;                          // setup mode drives no motor
  // The watchdog runs only once a host has set it (SSLBP's normal start: "setting the 8I20s
  // watchdog timer to 40 mS", manual, 8I20 DEVICE SPECIFIC SETUP), until the next reset.
  // Off: it runs from the first command in operate mode (a host that drives LBP directly).
  bool watchdog_set_by_host = false;
};

class Amplifier {
 public:
  Amplifier(RegisterMap map, EepromStore eeprom, World world, AmplifierSettings settings);

  // Power applied: NV -> working, sticky STATUS = EXTR only.
  void power_up(Clock::time_point now);
  // Processor reset: NV -> working, `sticky_cause` added to the sticky bits that survive.
  void reset(Clock::time_point now, std::uint16_t sticky_cause);

  // Samples the world and brings FAULT, STATUS, BUSV, TEMPERATURE and CLEARFAULT up to
  // `now`. Called before every command and whenever time advances.
  void update(Clock::time_point now);
  // A valid command arrived: feeds the operate-mode watchdog.
  void feed_watchdog(Clock::time_point now);
  // The host set the watchdog (see AmplifierSettings::watchdog_set_by_host).
  void set_watchdog_by_host() { watchdog_set_ = true; }

  lbp::Byte ram(std::uint16_t address) const { return ram_[address]; }
  // Whether a host write of `length` bytes at `address` would touch a read-only register.
  bool ram_write_protected(std::uint16_t address, std::size_t length) const;
  void write_ram(std::uint16_t address, lbp::ByteView data);

  EepromStore& eeprom() { return eeprom_; }
  const EepromStore& eeprom() const { return eeprom_; }
  World& world() { return world_; }
  const RegisterMap& map() const { return map_; }
  AmplifierSettings& settings() { return settings_; }

  // Raw value of a register by name (RAM or EEPROM image), for tests and the control channel.
  std::uint64_t value(std::string_view name) const;
  // Sets a register's raw value directly, bypassing protection (tests, control channel).
  void poke(std::string_view name, std::uint64_t value);

  std::uint16_t fault() const { return latched_faults_; }
  std::uint16_t status() const;
  // The fault output is "off" (fault signalled) when any unmasked fault is latched.
  bool fault_output_active() const;
  bool brake_on() const { return brake_on_; }
  // NVBAUDRATE index loaded at the last power-up/reset.
  unsigned baud_index() const { return baud_index_; }

  // How often the operate-mode watchdog has bitten (rising edges), and when it next would.
  std::uint64_t watchdog_bites() const { return watchdog_bites_; }
  std::optional<Clock::time_point> watchdog_due() const;
  bool watchdog_running() const;

  // The motor on this channel, from `now` on (replaces one attached before).
  void attach_motor(const motor::MotorParams& params, Clock::time_point now);
  // The attached motor, if any: its state (mechanical angle, speed, currents), its
  // description (encoder, Halls) and injected sensor faults. Up to date as of the last
  // update() / run_motor().
  const motor::Motor* motor() const { return motor_ ? &*motor_ : nullptr; }
  // The rotor's mechanical angle (turns, unwrapped) at `t`, for sensors read on another
  // card's clock: the motor's last state moved on (or back) at its speed to `t`. Cheap and
  // the same for the same `t` until the motor steps again; nullopt without a motor.
  std::optional<double> motor_turns_at(Clock::time_point t) const;
  // Changes the attached motor's parameters live (load step, brake, ...). Throws MotorError.
  void set_motor_params(const motor::MotorParams& params, Clock::time_point now);
  void set_motor_sensor_faults(motor::SensorFaults faults, Clock::time_point now);
  // Lets the motor run up to `now` with the drive as it is (also while the logic is off).
  void run_motor(Clock::time_point now);
  // The bridge switches off at `now` (logic power lost, a watchdog bite between updates).
  void bridge_off(Clock::time_point now);

  // CLEARFAULT never returns to 0 and nothing is cleared (injected firmware hang).
  void set_clearfault_stuck(bool stuck) { clearfault_stuck_ = stuck; }
  // When the pending CLEARFAULT completes, if one is pending.
  std::optional<Clock::time_point> clearfault_due() const {
    return clearfault_stuck_ ? std::nullopt : clear_due_;
  }

 private:
  void load_working_from_nv();
  std::uint16_t causes(const World::Sample& sample, Clock::time_point now) const;
  void update_brake(double bus_volts);
  void handle_clearfault(Clock::time_point now, std::uint16_t present);
  std::uint64_t read_raw(const Register& r) const;
  void write_raw(const Register& r, std::uint64_t value);
  std::uint16_t ram16(std::string_view name) const;
  std::optional<std::uint64_t> ram_value(std::string_view name) const;
  void step_motor_to(Clock::time_point t);
  std::uint16_t take_motor_causes();
  void command_motor();

  RegisterMap map_;
  EepromStore eeprom_;
  World world_;
  AmplifierSettings settings_;
  lbp::Bytes ram_ = lbp::Bytes(0x10000, 0);

  std::uint16_t latched_faults_ = 0;
  std::uint16_t sticky_ = 0;
  bool brake_on_ = false;
  double last_temperature_c_ = 0;
  unsigned baud_index_ = 9;
  std::optional<Clock::time_point> last_valid_command_;  // watchdog armed once set
  std::optional<Clock::time_point> clear_due_;
  bool clearfault_stuck_ = false;
  std::uint16_t previous_causes_ = 0;
  std::uint64_t watchdog_bites_ = 0;
  bool watchdog_set_ = false;
  std::optional<motor::Motor> motor_;
  Clock::time_point motor_time_{};
  Clock::time_point motor_attached_{};  // the motor's state().time_s counts from here
  double last_bus_volts_ = 0;
  std::uint16_t motor_causes_ = 0;  // seen while the motor ran, not yet latched
};

}  // namespace i20::sim
