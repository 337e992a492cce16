// SPDX-License-Identifier: GPL-2.0-or-later
#include "options.hpp"

#include <CLI/CLI.hpp>

namespace i20::app {

void add_target_options(CLI::App& app, GlobalOptions& o) {
  auto& t = o.target;
  auto* group = app.add_option_group("Target", "Which 8I20 to talk to (exactly one)");
  auto* port = group->add_option("--port,-p", t.port,
                                 "Serial device of the RS-422 adapter (3I21/3I22), e.g. /dev/ttyUSB0 or COM1 "
                                 "(= /dev/ttyS0); jumper W6 down "
                                 "(setup mode). Also an eth://IP/chN URL. `i20 ports` lists candidates; "
                                 "COMPORT is read when none is given");
  auto* sim = group->add_flag("--sim", t.sim, "Use the built-in 8I20 simulator (no hardware needed)");
  auto* eth =
      group->add_option("--eth", t.eth,
                        "Ethernet card (7I96S/7I92T) address IP[:PORT] hosting the 8I20 on a smart-serial "
                        "channel; see --channel");
  group->require_option(0, 1);
  app.add_option("--channel", t.channel, "SSERIAL channel of the 8I20 on the Ethernet card (0-7)")
      ->needs(eth)
      ->check(CLI::Range(0, 7));
  app.add_option("--sserial-port", t.sserial_port,
                 "SSERIAL port (instance) on the Ethernet card, e.g. 1 on a 7I92T")
      ->needs(eth)
      ->check(CLI::Range(0, 3));
  app.add_option("--sim-eeprom", t.sim_eeprom,
                 "EEPROM image file for --sim, so NV values persist between runs")
      ->needs(sim);
  app.add_option(
         "--sim-control", o.link.sim_control,
         "A simulator control line applied before the first command, e.g. \"busv 160\" (a card on a 120 V "
         "line) or \"enable off\"; repeatable, for --sim and sim targets. `i20sim --help` lists them")
      ->excludes(port)
      ->excludes(eth);  // a real card would silently ignore it: refused before any byte
  app.add_option("--baud", o.link.baud, "Serial baud rate; setup mode is always 115200 (manual)")
      ->needs(port)
      ->check(CLI::Range(1200u, 12000000u));
  app.add_option("--timeout", o.link.timeout_ms, "Reply timeout in ms on top of the wire time")
      ->check(CLI::Range(1, 10000));
  app.add_flag(
      "--take-over", o.link.take_over,
      "Ethernet only: use the smart-serial port even when another host (LinuxCNC) is driving it. That "
      "host's port stops: every 8I20 on it drops out and the machine faults");
  app.add_flag("--verbose,-v", o.verbose, "Say more about the link (adapter latency, statistics)");
}

void add_database_options(CLI::App& app, GlobalOptions& o) {
  app.add_option("--params", o.params_files,
                 "Parameter overlay file (YAML) on top of the built-in database; repeatable. Also read: "
                 "$I20_PARAMS and ~/.config/i20/params.yaml")
      ->check(CLI::ExistingFile);
  app.add_flag("--no-user-params", o.no_user_params, "Ignore $I20_PARAMS and ~/.config/i20/params.yaml");
}

Overrides overrides_of(const CLI::App& command) {
  auto has = [&](const char* name) {
    for (const CLI::App* app = &command; app != nullptr; app = app->get_parent())
      if (app->get_option_no_throw(name) != nullptr) return true;
    return false;
  };
  return {has("--take-over"), has("--force"), has("--allow-unverified")};
}

Overrides overrides_of_parsed(const CLI::App& app) {
  const CLI::App* command = &app;
  while (!command->get_subcommands().empty()) command = command->get_subcommands().front();
  return overrides_of(*command);
}

}  // namespace i20::app
