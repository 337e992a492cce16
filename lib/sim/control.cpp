// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/control.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "lbp/bytes.hpp"
#include "motor/error.hpp"
#include "motor/loader.hpp"
#include "sim/bits.hpp"
#include "sim/error.hpp"

namespace i20::sim {
namespace {

struct NamedFault {
  const char* name;
  std::uint16_t bit;
};

constexpr NamedFault kFaults[] = {
    {"watchdog", fault::kWatchdog},     {"noenable", fault::kNoEnable},
    {"overtemp", fault::kOverTemp},     {"overcurrent", fault::kOverCurrent},
    {"uloop", fault::kULoop},           {"vloop", fault::kVLoop},
    {"wloop", fault::kWLoop},           {"buslow", fault::kBusLow},
    {"bushigh", fault::kBusHigh},       {"busmax", fault::kBusMax},
    {"module", fault::kModule},         {"overrun", fault::kSerialOverrun},
    {"framing", fault::kSerialFraming},
};

const char* kHelp =
    "busv VOLTS                 motor bus voltage, e.g. busv 320\n"
    "temp CELSIUS               card temperature, e.g. temp 45\n"
    "enable on|off              enable input\n"
    "noise busv|temp AMPLITUDE  uniform noise on each sample, e.g. noise busv 0.5\n"
    "seed N                     restart the noise sequence from seed N\n"
    "fault NAME|BIT on|off      hold a hardware fault cause, e.g. fault overcurrent on\n"
    "                           (watchdog noenable overtemp overcurrent uloop vloop wloop buslow\n"
    "                            bushigh busmax module overrun framing, or a bit number)\n"
    "corrupt RATE               probability 0..1 that a reply byte is corrupted\n"
    "drop RATE                  probability 0..1 that a reply is lost\n"
    "delay MS                   extra latency before each reply, 0..60000\n"
    "reset-after N|off          reset the card right after N more commands\n"
    "clearfault-stuck on|off    CLEARFAULT never returns to 0\n"
    "eeprom-power-loss off|lost|torn   power fails during the next EEPROM write\n"
    "mute-after N|off           execute N more commands, then stop answering\n"
    "power off|on|cycle         switch the card's logic power\n"
    "get NAME                   raw value of a parameter, e.g. get FAULT\n"
    "set NAME VALUE             force a parameter's raw value (bypasses protection)\n"
    "motor KEY VALUE            change the attached motor live, as its file writes it, e.g.\n"
    "                           motor load 0.3Nm (a load step), motor brake.engaged true,\n"
    "                           motor friction.coulomb 0.05Nm (keys: motors/README.md)\n"
    "motor fault hall-stuck|encoder-lost on|off   freeze the Hall code or the encoder count\n"
    "motor                      the motor's state: angle, speed, electrical angle, encoder, Halls, currents\n"
    "show                       the state at a glance (with the motor's, if one is attached)\n"
    "help                       this list\n";

std::vector<std::string> words(std::string_view line) {
  std::istringstream in{std::string(line)};
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

[[noreturn]] void fail(const std::string& why) {
  throw ControlError(why);
}

std::string format_limit(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Reply delays beyond a minute are no test of a host's timeout, and a duration_cast of
// 1e300 ms overflows.
constexpr double kMaxDelayMs = 60000;

void need(const std::vector<std::string>& w, std::size_t count, const char* form) {
  if (w.size() != count) fail(std::string("expected '") + form + "'");
}

// A finite number: "nan" and "inf" would reach the world's integer conversions.
double number(const std::string& text, const char* form) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  fail("'" + text + "' is not a number in '" + form + "'");
}

// A finite number within lo..hi.
double number_in(const std::string& text, double lo, double hi, const char* form) {
  const double v = number(text, form);
  if (v < lo || v > hi)
    fail(text + " is outside " + format_limit(lo) + ".." + format_limit(hi) + " in '" + form + "'");
  return v;
}

// Decimal or 0x hexadecimal, no sign (stoull would wrap "-1" to 2^64-1).
std::uint64_t integer(const std::string& text, const char* form) {
  try {
    std::size_t used = 0;
    const bool digits_first = !text.empty() && std::isdigit(static_cast<unsigned char>(text[0]));
    const unsigned long long v = std::stoull(text, &used, 0);
    if (digits_first && used == text.size()) return v;
  } catch (const std::exception&) {
  }
  fail("'" + text + "' is not a whole number in '" + form + "'");
}

bool on_off(const std::string& text, const char* form) {
  if (text == "on" || text == "1" || text == "true") return true;
  if (text == "off" || text == "0" || text == "false") return false;
  fail("'" + text + "' is neither on nor off in '" + form + "'");
}

double rate(const std::string& text, const char* form) {
  const double r = number(text, form);
  if (r < 0 || r > 1) fail("rate " + text + " is outside 0..1 in '" + form + "'");
  return r;
}

std::optional<std::uint64_t> count_or_off(const std::string& text, const char* form) {
  if (text == "off") return std::nullopt;
  return integer(text, form);
}

std::uint16_t fault_bit(const std::string& text) {
  for (const auto& f : kFaults)
    if (text == f.name) return f.bit;
  const auto n = integer(text, "fault NAME|BIT on|off");
  if (n > 15) fail("fault bit " + text + " is outside 0..15");
  return static_cast<std::uint16_t>(1u << n);
}

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string world_command(Virtual8i20& card, const std::vector<std::string>& w) {
  auto& s = card.world().settings();
  const std::string& c = w[0];
  if (c == "busv") {
    need(w, 2, "busv VOLTS");
    s.bus_volts = number(w[1], "busv VOLTS");
  } else if (c == "temp") {
    need(w, 2, "temp CELSIUS");
    s.temperature_c = number(w[1], "temp CELSIUS");
  } else if (c == "enable") {
    need(w, 2, "enable on|off");
    s.enable = on_off(w[1], "enable on|off");
  } else if (c == "noise") {
    need(w, 3, "noise busv|temp AMPLITUDE");
    const double a = number(w[2], "noise busv|temp AMPLITUDE");
    if (w[1] == "busv")
      s.bus_noise_volts = a;
    else if (w[1] == "temp")
      s.temp_noise_c = a;
    else
      fail("expected 'noise busv|temp AMPLITUDE'");
  } else if (c == "seed") {
    need(w, 2, "seed N");
    s.noise_seed = integer(w[1], "seed N");
    card.world().reseed();
  } else if (c == "fault") {
    need(w, 3, "fault NAME|BIT on|off");
    const std::uint16_t bit = fault_bit(w[1]);
    if (on_off(w[2], "fault NAME|BIT on|off"))
      s.forced_faults |= bit;
    else
      s.forced_faults &= static_cast<std::uint16_t>(~bit);
  } else {
    return {};
  }
  return "ok";
}

std::string injection_command(Virtual8i20& card, const std::vector<std::string>& w) {
  auto& inj = card.injection();
  const std::string& c = w[0];
  if (c == "corrupt") {
    need(w, 2, "corrupt RATE");
    inj.corrupt_rate = rate(w[1], "corrupt RATE");
  } else if (c == "drop") {
    need(w, 2, "drop RATE");
    inj.drop_rate = rate(w[1], "drop RATE");
  } else if (c == "delay") {
    need(w, 2, "delay MS");
    inj.reply_delay = std::chrono::duration_cast<Duration>(
        std::chrono::duration<double, std::milli>(number_in(w[1], 0, kMaxDelayMs, "delay MS")));
  } else if (c == "reset-after") {
    need(w, 2, "reset-after N|off");
    inj.reset_after_commands = count_or_off(w[1], "reset-after N|off");
  } else if (c == "clearfault-stuck") {
    need(w, 2, "clearfault-stuck on|off");
    inj.clearfault_stuck = on_off(w[1], "clearfault-stuck on|off");
  } else if (c == "eeprom-power-loss") {
    need(w, 2, "eeprom-power-loss off|lost|torn");
    if (w[1] == "off")
      inj.eeprom_power_loss = EepromPowerLoss::None;
    else if (w[1] == "lost")
      inj.eeprom_power_loss = EepromPowerLoss::Lost;
    else if (w[1] == "torn")
      inj.eeprom_power_loss = EepromPowerLoss::Torn;
    else
      fail("expected 'eeprom-power-loss off|lost|torn'");
  } else if (c == "mute-after") {
    need(w, 2, "mute-after N|off");
    inj.answer_limit = count_or_off(w[1], "mute-after N|off");
  } else {
    return {};
  }
  return "ok";
}

std::string card_command(Virtual8i20& card, const std::vector<std::string>& w, Clock::time_point now) {
  const std::string& c = w[0];
  if (c == "power") {
    need(w, 2, "power off|on|cycle");
    if (w[1] == "off")
      card.power_off();
    else if (w[1] == "cycle" || (w[1] == "on" && !card.powered()))
      card.power_cycle(now);
    else if (w[1] != "on")
      fail("expected 'power off|on|cycle'");
    return "ok";
  }
  if (c == "get") {
    need(w, 2, "get NAME");
    card.advance(now);
    try {
      return std::to_string(card.amplifier().value(upper(w[1])));
    } catch (const ConfigError& e) {
      fail(e.what());
    }
  }
  if (c == "set") {
    need(w, 3, "set NAME VALUE");
    try {
      card.amplifier().poke(upper(w[1]), integer(w[2], "set NAME VALUE"));
    } catch (const ConfigError& e) {
      fail(e.what());
    }
    return "ok";
  }
  if (c == "show") {
    card.advance(now);
    return describe_state(card);
  }
  if (c == "help") return control_help();
  return {};
}

std::string motor_command(Virtual8i20& card, const std::vector<std::string>& w, Clock::time_point now) {
  if (w[0] != "motor") return {};
  const motor::Motor* m = card.motor();
  if (!m) fail("no motor is attached to this 8I20 (i20sim --motor FILE.yaml)");
  card.advance(now);
  if (w.size() == 1) return describe_motor(*m);
  if (w[1] == "fault") {
    const char* form = "motor fault hall-stuck|encoder-lost on|off";
    need(w, 4, form);
    motor::SensorFaults faults = m->sensor_faults();
    const bool on = on_off(w[3], form);
    if (w[2] == "hall-stuck")
      faults.hall_stuck = on;
    else if (w[2] == "encoder-lost")
      faults.encoder_lost = on;
    else
      fail(std::string("expected '") + form + "'");
    card.amplifier().set_motor_sensor_faults(faults, now);
    return "ok";
  }
  need(w, 3, "motor KEY VALUE");
  try {
    motor::MotorParams params = m->params();
    motor::set_motor_key(params, w[1], w[2], true);
    card.amplifier().set_motor_params(params, now);
  } catch (const motor::MotorError& e) {
    fail(e.what());
  }
  card.advance(now);
  return "ok";
}

}  // namespace

std::string apply_control(Virtual8i20& card, std::string_view line, Clock::time_point now) {
  const auto w = words(line.substr(0, line.find('#')));
  if (w.empty()) return {};
  card.advance(now);
  for (auto* handler : {world_command, injection_command}) {
    if (auto answer = handler(card, w); !answer.empty()) {
      card.advance(now);
      return answer;
    }
  }
  if (auto answer = card_command(card, w, now); !answer.empty()) return answer;
  if (auto answer = motor_command(card, w, now); !answer.empty()) return answer;
  fail("unknown control command '" + w[0] + "': try 'help'");
}

std::string control_help() {
  return kHelp;
}

namespace {
const char* nv_access_name(lbp::local::NvAccess mode) {
  switch (mode) {
    case lbp::local::NvAccess::Ram: return "ram";
    case lbp::local::NvAccess::Eeprom: return "eeprom";
    case lbp::local::NvAccess::Flash: return "flash";
  }
  return "?";
}
}  // namespace

std::string describe_state(Virtual8i20& card) {
  const auto& s = card.world().settings();
  const auto& amp = card.amplifier();
  char buf[384];
  std::snprintf(buf, sizeof buf,
                "power=%s mode=%s baud=%u busv=%.2fV temp=%.2fC enable=%s fault=%s status=%s "
                "lbp_status=0x%02X fault_output=%s brake=%s crc_errors=%u nv_access=%s rpcmem=%s",
                card.powered() ? "on" : "off", card.mode() == FramingMode::Setup ? "setup" : "operate",
                card.baud(), s.bus_volts, s.temperature_c, s.enable ? "on" : "off",
                lbp::hex_value(amp.fault(), 4).c_str(), lbp::hex_value(amp.status(), 4).c_str(),
                card.lbp_registers().status, amp.fault_output_active() ? "fault" : "ok",
                amp.brake_on() ? "on" : "off", card.lbp_registers().crc_errors,
                nv_access_name(card.lbp_registers().nv_access), card.lbp_registers().rpcmem ? "on" : "off");
  std::string out = buf;
  if (const motor::Motor* m = card.motor()) {
    out += ' ';  // apart: GCC 12's -O3 -Wrestrict misfires on `" " + std::string&&`
    out += describe_motor(*m);
  }
  return out;
}

std::string describe_motor(const motor::Motor& m) {
  const auto& s = m.state();
  const auto sensors = m.read_sensors();
  std::string encoder = "none", halls = "none";
  if (sensors.encoder_count)
    encoder = std::to_string(*sensors.encoder_count) + (m.sensor_faults().encoder_lost ? "(lost)" : "");
  if (sensors.hall_code) {
    halls.clear();
    for (int bit = 2; bit >= 0; --bit) halls += (*sensors.hall_code >> bit) & 1u ? '1' : '0';
    if (m.sensor_faults().hall_stuck) halls += "(stuck)";
  }
  constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
  constexpr double kRadPerSToRpm = 60.0 / (2 * 3.14159265358979323846);
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "motor_angle=%.6fturns speed=%.1frpm electrical=%.1fdeg encoder=%s halls=%s iu=%.3fA iv=%.3fA "
      "iw=%.3fA id=%.3fA iq=%.3fA torque=%.4fNm output=%s load=%gNm brake=%s",
      s.angle_turns, s.speed_rad_s * kRadPerSToRpm, s.electrical_angle_rad * kRadToDeg, encoder.c_str(),
      halls.c_str(), s.phase_a[0], s.phase_a[1], s.phase_a[2], s.current_a.d, s.current_a.q, s.torque_nm,
      m.drive().output_on ? "on" : "off", m.params().load_nm,
      m.params().brake_engaged ? "engaged" : "released");
  std::string out = buf;
  const auto& machine = m.params().machine;
  if (motor::reflected_load_inertia(m.params()) > 0 || machine.lead_m_per_turn > 0) {
    // The machine behind the motor: where its load is (it lags on a compliant coupling).
    std::snprintf(buf, sizeof buf, " load_angle=%.6fturns load_speed=%.1frpm", s.load_angle_turns,
                  s.load_speed_rad_s * kRadPerSToRpm);
    out += buf;
    if (machine.lead_m_per_turn > 0) {
      std::snprintf(buf, sizeof buf, " position=%.4fmm", s.machine_position_m * 1e3);
      out += buf;
    }
  }
  return out;
}

}  // namespace i20::sim
