// What every app shares: the global options (where the 8I20 is, which database), and a
// session that opens the link, loads the database and identifies the card on first use.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "device/amp.hpp"
#include "link/link.hpp"
#include "params/param_db.hpp"

namespace CLI {
class App;
}

namespace i20::app {

struct GlobalOptions {
  std::string port;           // serial device (or COMn)
  bool sim = false;           // the built-in simulator, in-process
  std::string sim_eeprom;     // EEPROM image file for --sim (persists NV values)
  std::string eth;            // Ethernet card address (7I96S / 7I92T)
  unsigned channel = 0;       // SSERIAL channel on the Ethernet card
  unsigned sserial_port = 0;  // SSERIAL instance on the Ethernet card (7I92T: 0 or 1)
  unsigned baud = 115200;
  unsigned timeout_ms = 50;
  std::vector<std::string> params_files;
  bool no_user_params = false;
  bool json = false;
  bool verbose = false;
};

// Adds --port/--sim/--eth/... to an app (the i20 umbrella, wpd, rpd).
void add_target_options(CLI::App& app, GlobalOptions& options);
void add_database_options(CLI::App& app, GlobalOptions& options);

// The built-in database plus the per-user overlay and --params files, in that order.
params::ParamDb load_database(const GlobalOptions& options);

// Opens the link the options describe. Throws i20::Error with advice when no target was
// given or it cannot be opened.
std::unique_ptr<link::Link> open_link(const GlobalOptions& options, const params::ParamDb& db);

class Session {
 public:
  explicit Session(GlobalOptions options);
  ~Session();

  const GlobalOptions& options() const { return options_; }
  params::ParamDb& db();
  link::Link& link();
  // The card client (it identifies the card, SWREVISION selecting the database map, on
  // its first read or checked write).
  device::Amp8i20& amp();
  // The link if it has been opened, else nullptr (for statistics).
  const link::Link* link_if_open() const { return link_.get(); }
  // Drops the link and the card client so the next use opens them again (after an
  // adapter was unplugged and replugged, or the card reset).
  void reconnect();
  // Link and adapter notes (e.g. low-latency mode not available), for --verbose.
  std::vector<std::string> notes() const;

 private:
  GlobalOptions options_;
  std::unique_ptr<params::ParamDb> db_;
  std::unique_ptr<link::Link> link_;
  std::unique_ptr<device::Amp8i20> amp_;
};

}  // namespace i20::app
