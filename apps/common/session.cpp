#include "session.hpp"

#include <CLI/CLI.hpp>

#include "eth/target.hpp"
#include "interrupt.hpp"
#include "link/serial_link.hpp"
#include "targets.hpp"

namespace i20::app {
namespace {

// WPD/RPD users write COM1; on Linux that is /dev/ttyS0 (a 3I22 shows up as ttyUSBn).
std::string port_path(const std::string& port) {
  if (port.size() > 3 && (port.rfind("COM", 0) == 0 || port.rfind("com", 0) == 0)) {
    try {
      const int n = std::stoi(port.substr(3));
      if (n >= 1) return "/dev/ttyS" + std::to_string(n - 1);
    } catch (const std::exception&) {
    }
  }
  return port;
}

}  // namespace

void add_target_options(CLI::App& app, GlobalOptions& o) {
  auto* group = app.add_option_group("Target", "Which 8I20 to talk to (exactly one)");
  auto* port =
      group->add_option("--port,-p", o.port,
                        "Serial device of the RS-422 adapter (3I21/3I22), e.g. /dev/ttyUSB0; jumper W6 "
                        "down (setup mode). `i20 ports` lists candidates");
  auto* sim = group->add_flag("--sim", o.sim, "Use the built-in 8I20 simulator (no hardware needed)");
  auto* eth =
      group->add_option("--eth", o.eth,
                        "Ethernet card (7I96S/7I92T) address IP[:PORT] hosting the 8I20 on a smart-serial "
                        "channel; see --channel");
  group->require_option(0, 1);
  app.add_option("--channel", o.channel, "SSERIAL channel of the 8I20 on the Ethernet card (0-7)")
      ->needs(eth)
      ->check(CLI::Range(0, 7));
  app.add_option("--sserial-port", o.sserial_port,
                 "SSERIAL port (instance) on the Ethernet card, e.g. 1 on a 7I92T")
      ->needs(eth)
      ->check(CLI::Range(0, 3));
  app.add_option("--sim-eeprom", o.sim_eeprom,
                 "EEPROM image file for --sim, so NV values persist between runs")
      ->needs(sim);
  app.add_option("--baud", o.baud, "Serial baud rate; setup mode is always 115200 (manual)")
      ->needs(port)
      ->check(CLI::PositiveNumber);
  app.add_option("--timeout", o.timeout_ms, "Reply timeout in ms on top of the wire time")
      ->check(CLI::Range(1, 10000));
  app.add_flag("--verbose,-v", o.verbose, "Say more about the link (adapter latency, statistics)");
}

void add_database_options(CLI::App& app, GlobalOptions& o) {
  app.add_option("--params", o.params_files,
                 "Parameter overlay file (YAML) on top of the built-in database; repeatable. Also read: "
                 "$I20_PARAMS and ~/.config/i20/params.yaml")
      ->check(CLI::ExistingFile);
  app.add_flag("--no-user-params", o.no_user_params, "Ignore $I20_PARAMS and ~/.config/i20/params.yaml");
}

params::ParamDb load_database(const GlobalOptions& options) {
  auto db = params::ParamDb::builtin();
  if (!options.no_user_params)
    for (const auto& path : params::default_overlay_paths()) db.apply_overlay_file(path);
  for (const auto& path : options.params_files) db.apply_overlay_file(path);
  return db;
}

std::unique_ptr<link::Link> open_link(const GlobalOptions& o, const params::ParamDb& db) {
  link::PipelinedLinkOptions link_options;
  link_options.base_timeout = std::chrono::milliseconds(o.timeout_ms);
  if (o.sim) return open_sim_link(db, o.sim_eeprom, link_options);
  if (!o.eth.empty()) return open_eth_link(o.eth, o.sserial_port, o.channel, o.timeout_ms);
  // eth:// URLs work wherever a port is accepted (fleet targets, COMPORT).
  if (eth::is_eth_url(o.port)) return open_eth_link(o.port, 0, 0, o.timeout_ms);
  if (!o.port.empty()) {
    link::SerialOptions serial;
    serial.baud = o.baud;
    return link::open_serial_link(port_path(o.port), link_options, serial);
  }
  throw UsageError(
      "no 8I20 given: use --port /dev/ttyUSB0 (see `i20 ports`), --sim for the built-in simulator, or --eth "
      "IP "
      "for an 8I20 behind a 7I96S/7I92T");
}

Session::Session(GlobalOptions options) : options_(std::move(options)) {}
Session::~Session() = default;

params::ParamDb& Session::db() {
  if (!db_) db_ = std::make_unique<params::ParamDb>(load_database(options_));
  return *db_;
}

link::Link& Session::link() {
  if (!link_) link_ = open_link(options_, db());
  return *link_;
}

device::Amp8i20& Session::amp() {
  if (!amp_) {
    // No separate identify(): the first read or checked write identifies the card
    // within its own exchange.
    amp_ = std::make_unique<device::Amp8i20>(link(), db(), &install_interrupt_handler());
  }
  return *amp_;
}

void Session::reconnect() {
  amp_.reset();
  link_.reset();
}

std::vector<std::string> Session::notes() const {
  return link_ ? link_->notes() : std::vector<std::string>{};
}

}  // namespace i20::app
