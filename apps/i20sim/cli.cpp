// SPDX-License-Identifier: GPL-2.0-or-later
#include "cli.hpp"

#include <CLI/CLI.hpp>
#include <iostream>

#include "ethsim/board_control.hpp"
#include "motor/error.hpp"
#include "motor/loader.hpp"
#include "params/param_db.hpp"
#include "params/text.hpp"
#include "parse_error.hpp"
#include "sim/control.hpp"
#include "sim/param_map.hpp"
#include "version/build_info.hpp"

namespace i20::sim::app {
namespace {

const char* kDescription =
    "i20sim: a virtual Mesa 8I20 servo amplifier on a pseudo-terminal, or several behind a virtual\n"
    "7I96S/7I92T Ethernet card (--eth).\n"
    "Strict like the real card in setup mode (115200 8N1, CRC-8, pre-parse framing, command timeout,\n"
    "NV values only after reset), with switches to script the world and inject faults.\n\n"
    "Examples:\n"
    "  i20sim --pty                                  serve; the first stdout line is the port path\n"
    "  i20sim --pty --eeprom card.eeprom             NV values persist in card.eeprom\n"
    "  i20sim --pty --operate --motor motors/small-servo.yaml\n"
    "                                                a motor the card drives (ANGLE, QSETPOINT);\n"
    "                                                echo 'motor load 0.3Nm' > the --control FIFO\n"
    "  i20sim --pty --busv 24 --enable off           a bench card: low bus, no enable\n"
    "  i20sim --pty --random-map 7                   other working addresses, other SWREVISION\n"
    "  i20sim --pty --wire-time --turnaround-us 1000 real line timing behind a USB adapter\n"
    "  i20sim --pty --drop 0.05 --seed 3             lose 5% of the replies, reproducibly\n"
    "  i20sim --pty --control /tmp/i20.ctl &  echo 'busv 400' > /tmp/i20.ctl\n"
    "  i20sim --print-map --random-map 7             show the map and the preloaded RPC table\n"
    "  i20sim --eth 127.0.0.1:0                      a virtual 7I96S with the 8I20 on SSERIAL channel 0\n"
    "  i20sim --eth 127.0.0.1:0 --card 7i92t --channels 4 --control /tmp/i20.ctl\n"
    "                                                four 8I20s on a 7I92T port; echo 'ch 2 busv 24' > "
    "/tmp/i20.ctl\n"
    "  i20sim --eth 127.0.0.1:0 --running-host       beside a running machine (LinuxCNC stand-in)\n\n"
    "While serving, lines on stdin (and on the --control FIFO) change the world and the\n"
    "injection switches; answers go to stdout. With --eth a line goes to the first 8I20, or to\n"
    "the one it names:\n";

using Ms = std::chrono::duration<double, std::milli>;

Duration ms(double value) {
  return std::chrono::duration_cast<Duration>(Ms(value));
}

struct Raw {
  std::string eeprom, params, address_map, enable = "on", power_loss = "off";
  std::optional<std::uint64_t> random_map, reset_after, mute_after;
  std::uint64_t unit_number = 0x00012345;
  double eeprom_word_ms = 2, clearfault_ms = 5, watchdog_ms = 40, reset_ms = 1, delay_ms = 0,
         turnaround_us = 0;
  std::vector<std::string> faults;
  std::vector<std::string> motors;
};

RegisterMap build_map(const Raw& raw) {
  // The YAML is the single source of addresses; user overlays ($I20_PARAMS) do not apply
  // to the simulator, which stands for the card itself.
  RegisterMap map = register_map_from(raw.params.empty() ? params::ParamDb::builtin()
                                                         : params::ParamDb::load_file(raw.params));
  if (!raw.address_map.empty()) map = RegisterMap::with_overrides(std::move(map), raw.address_map);
  if (raw.random_map) map = map.shuffled(*raw.random_map);
  return map;
}

void add_options(CLI::App& app, Invocation& o, Raw& raw) {
  auto& d = o.sim.device;
  auto& w = d.world;
  auto& inj = d.injection;
  app.add_flag("--pty", o.pty,
               "Serve on a new pseudo-terminal; its path is printed alone on stdout's first line");
  auto* eth =
      app.add_option("--eth", o.eth_options.listen,
                     "Serve a virtual 7I96S on UDP at ADDR[:PORT] (default port 27181) with the 8I20 on "
                     "SSERIAL channel 0; prints ADDR:PORT on the first line. Instead of --pty")
          ->excludes("--pty");
  app.add_option("--card", o.eth_options.card,
                 "Virtual Ethernet card for --eth: 7i96s, 7i92t, or 7i92t-servo (an encoder, Halls and an "
                 "8I20 per axis)")
      ->needs(eth)
      ->check(CLI::IsMember({"7i96s", "7I96S", "7i92t", "7I92T", "7i92t-servo"}));
  app.add_option("--channels", o.eth_options.channels,
                 "8I20s on the card's port 0 (channels 0..N-1), for --eth")
      ->needs(eth)
      ->check(CLI::Range(1, 8));
  app.add_flag(
         "--running-host", o.eth_options.running_host,
         "With --eth: another host already runs the 8I20s in normal mode, DOITs every 1 ms, as LinuxCNC "
         "would (control: host on|off)")
      ->needs(eth);
  app.add_flag("--print-map", o.print_map, "Print the register map and the preloaded RPC table, then exit");
  app.add_flag("--trace", o.trace, "Log every command, reply and framing event to stderr");
  app.add_option("--control", o.server.control_fifo,
                 "Also read control lines from this FIFO (created if missing, removed at exit if created), "
                 "e.g. /tmp/i20.ctl; with --pty or --eth");
  app.add_flag(
      "--no-stdin", [&](std::int64_t) { o.server.read_stdin = false; },
      "Do not read control lines from stdin");

  const char* card = "Card";
  app.add_option("--eeprom", raw.eeprom,
                 "EEPROM image file; created with defaults if missing, written through on every NV write, "
                 "e.g. card.eeprom")
      ->group(card);
  app.add_option("--params", raw.params,
                 "Parameter database YAML the map is built from (default: the built-in params/8i20.yaml)")
      ->group(card);
  app.add_option("--address-map", raw.address_map,
                 "Override addresses: lines 'FAULT = 0x0900', 'revision = 0xE121'")
      ->group(card);
  app.add_option("--random-map", raw.random_map,
                 "Shuffle the working RAM addresses with this seed (SWREVISION changes too), e.g. 7")
      ->group(card);
  app.add_option("--unit-number", raw.unit_number, "UNITNUMBER the card reports, e.g. 0x00012345")
      ->group(card);
  app.add_flag(
         "--operate", [&](std::int64_t) { d.mode = FramingMode::Operate; },
         "Operate mode: timing-only framing at NVBAUDRATE, 40 ms watchdog (default: setup mode)")
      ->group(card);
  app.add_option("--rx-buffer", d.rx_buffer_bytes,
                 "Receive buffer in bytes; more is dropped (LBP status bit 4)")
      ->capture_default_str()
      ->group(card);
  app.add_option("--eeprom-word-ms", raw.eeprom_word_ms, "EEPROM write time per 16-bit word, ms")
      ->capture_default_str()
      ->group(card);
  app.add_option("--clearfault-delay-ms", raw.clearfault_ms, "Delay before the card acts on CLEARFAULT, ms")
      ->capture_default_str()
      ->group(card);
  app.add_option("--watchdog-ms", raw.watchdog_ms, "Operate-mode watchdog, ms")
      ->capture_default_str()
      ->group(card);
  app.add_option("--reset-ms", raw.reset_ms, "Time the card is deaf after 0xFE 0x5A, ms")
      ->capture_default_str()
      ->group(card);

  const char* world = "World";
  app.add_option(
         "--motor", raw.motors,
         "A motor on an 8I20's outputs, from a motor file (see motors/README.md), e.g. "
         "motors/small-servo.yaml; the card drives it in operate mode. With --eth repeatable: each on its "
         "file's channel, its encoder and Halls on the inputs of that channel's axis (--card 7i92t-servo: "
         "axis k is channel k)")
      ->group(world);
  app.add_option("--busv", w.bus_volts, "Motor bus voltage, V, e.g. --busv 48")
      ->capture_default_str()
      ->group(world);
  app.add_option("--temp", w.temperature_c, "Card temperature, C")->capture_default_str()->group(world);
  app.add_option("--enable", raw.enable, "Enable input: on|off")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str()
      ->group(world);
  app.add_option("--busv-noise", w.bus_noise_volts, "+- noise on BUSV samples, V")->group(world);
  app.add_option("--temp-noise", w.temp_noise_c, "+- noise on TEMPERATURE samples, C")->group(world);
  app.add_option("--noise-seed", w.noise_seed, "Seed of the measurement noise")->group(world);
  app.add_option("--fault", raw.faults,
                 "Hold a hardware fault cause (repeatable): overcurrent, module, uloop, overrun, framing, "
                 "... or a bit")
      ->group(world);

  const char* inject = "Fault injection";
  app.add_option("--corrupt", inj.corrupt_rate, "Probability 0..1 that a reply byte is corrupted, e.g. 0.01")
      ->check(CLI::Range(0.0, 1.0))
      ->group(inject);
  app.add_option("--drop", inj.drop_rate, "Probability 0..1 that a reply is lost (the command still runs)")
      ->check(CLI::Range(0.0, 1.0))
      ->group(inject);
  app.add_option("--delay-ms", raw.delay_ms, "Extra latency before every reply, ms")->group(inject);
  app.add_option("--reset-after", raw.reset_after, "Reset the card right after N commands (mid-batch reset)")
      ->group(inject);
  app.add_flag("--clearfault-stuck", inj.clearfault_stuck, "CLEARFAULT never returns to 0")->group(inject);
  app.add_option("--eeprom-power-loss", raw.power_loss,
                 "Power fails during the first EEPROM write: off|lost|torn")
      ->check(CLI::IsMember({"off", "lost", "torn"}))
      ->group(inject);
  app.add_option("--mute-after", raw.mute_after, "Execute N commands, then stop answering")->group(inject);
  app.add_option("--seed", inj.seed, "Seed of the injection randomness")->group(inject);

  const char* wire = "Wire time";
  app.add_flag("--wire-time", o.sim.wire.emulate_wire_time, "Each byte takes 10 bit times at the card's baud")
      ->group(wire);
  app.add_option("--turnaround-us", raw.turnaround_us,
                 "Extra latency per reply burst (a USB adapter adds ~1000 us)")
      ->group(wire);
}

void apply(Invocation& o, const Raw& raw) {
  auto& d = o.sim.device;
  d.map = build_map(raw);
  if (!raw.eeprom.empty()) d.eeprom_file = raw.eeprom;
  d.amplifier.unit_number = static_cast<std::uint32_t>(raw.unit_number);
  d.eeprom_word_time = ms(raw.eeprom_word_ms);
  d.amplifier.clearfault_delay = ms(raw.clearfault_ms);
  d.amplifier.watchdog = ms(raw.watchdog_ms);
  d.reset_time = ms(raw.reset_ms);
  d.world.enable = raw.enable == "on";
  d.injection.reply_delay = ms(raw.delay_ms);
  d.injection.reset_after_commands = raw.reset_after;
  d.injection.answer_limit = raw.mute_after;
  d.injection.eeprom_power_loss = raw.power_loss == "lost"   ? EepromPowerLoss::Lost
                                  : raw.power_loss == "torn" ? EepromPowerLoss::Torn
                                                             : EepromPowerLoss::None;
  for (const auto& path : raw.motors) {
    auto params = motor::load_motor_file(path);
    if (o.eth) {
      for (const auto& other : o.eth_options.motors)
        if (other.channel == params.channel)
          throw motor::MotorError(path + ": channel " + std::to_string(params.channel) +
                                  " already has a motor (one motor per 8I20)");
      o.eth_options.motors.push_back(std::move(params));
      continue;
    }
    // A pty is one 8I20 on its own line: the file's channel (a place on an FPGA card's
    // SSERIAL port) does not apply.
    if (raw.motors.size() > 1)
      throw motor::MotorError(path +
                              ": the serial simulator has one 8I20, so one motor; several axes need --eth");
    d.motor = std::move(params);
  }
  o.sim.wire.turnaround =
      std::chrono::duration_cast<Duration>(std::chrono::duration<double, std::micro>(raw.turnaround_us));
}

}  // namespace

std::optional<int> parse_command_line(int argc, char** argv, Invocation& out) {
  CLI::App app(
      std::string(kDescription) + ethsim::board_control_help() + "and for every 8I20:\n" + control_help(),
      "i20sim");
  app.set_version_flag("--version", "i20sim " + std::string(build::kVersion), "Print the version and exit");
  Raw raw;
  add_options(app, out, raw);
  try {
    app.parse(argc, argv);
    out.eth = app.count("--eth") > 0;
    if (!out.pty && !out.eth && !out.print_map)
      throw CLI::ValidationError("nothing to do: give --pty or --eth ADDR to serve (or --print-map)");
    apply(out, raw);
    for (const auto& f : raw.faults) out.startup_control.push_back("fault " + f + " on");
  } catch (const CLI::ParseError& e) {
    return i20::app::report_parse_error(app, e, "i20sim");
  } catch (const Error& e) {  // unreadable --params / --address-map, bad map
    std::cerr << "i20sim: " << params::printable(e.what()) << std::endl;
    return 2;
  }
  return std::nullopt;
}

}  // namespace i20::sim::app
