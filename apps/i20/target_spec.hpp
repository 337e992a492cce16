// Where the profile commands send their work: the `--target` strings, parsed in this one
// place, and a connection to one card with its own link, database copy and card client
// (so fleet threads share nothing).
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "device/amp.hpp"
#include "link/link.hpp"
#include "params/param_db.hpp"
#include "session.hpp"

namespace i20::cli {

struct TargetSpec {
  std::string text;            // as given, for tables and messages: "/dev/ttyUSB0", "sim:a.eeprom"
  app::GlobalOptions options;  // the global options with only this target set
  // Targets with the same key share one physical line (a serial port, an Ethernet card):
  // the fleet runs them one after the other. Different keys run concurrently.
  std::string link_key;
};

// The target forms, for help texts and error messages.
extern const char* const kTargetForms;

// One `--target` string. Forms:
//   /dev/ttyUSB0, COM3, any other path   a serial RS-422 adapter (setup mode, W6 down)
//   sim                                  a fresh in-process simulator
//   sim:FILE                             an in-process simulator whose EEPROM lives in FILE
//   eth://IP[:UDPPORT][/portP][/chN]    an SSERIAL channel of a 7I96S/7I92T (the URL goes
//                                        to app::open_link, which knows its syntax)
// `index` makes every plain `sim` its own line. Throws UsageError for a malformed string.
TargetSpec parse_target(const std::string& text, const app::GlobalOptions& base, std::size_t index = 0);

// The global options that name this target, for commands in advice lines:
// "--port /dev/ttyUSB0", "--sim --sim-eeprom a.eeprom", "--eth 10.0.0.2 --channel 1".
std::string command_flags(const TargetSpec& target);

// Every `--target`, or the one the global --port/--sim/--eth options name when there is no
// `--target`. Throws UsageError for a target given twice, for both forms at once, or none.
std::vector<TargetSpec> resolve_targets(const std::vector<std::string>& texts,
                                        const app::GlobalOptions& base);

// One card: a link, a private copy of the database (identify() selects the card's firmware
// in it) and the card client on top.
struct Connection {
  params::ParamDb db;
  std::unique_ptr<link::Link> link;
  std::unique_ptr<device::Amp8i20> amp;
};

// Opens the link and identifies the card (asking up to `attempts` times: a garbled reply
// to a read is harmless). `cancel` is polled by the card client between exchanges
// (nullptr: never cancelled). Throws i20::Error (link::LinkError when the line fails).
std::unique_ptr<Connection> connect(const TargetSpec& target, const params::ParamDb& db,
                                    const std::atomic<bool>* cancel, unsigned attempts = 3);

}  // namespace i20::cli
