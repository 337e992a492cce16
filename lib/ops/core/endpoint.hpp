// SPDX-License-Identifier: GPL-2.0-or-later
// Where an 8I20 is, in one place: every program parses its target here (--port, --sim,
// --eth, eth:// URLs, COMn, fleet targets) and opens the link here.
//
// Forms:
//   /dev/ttyUSB0, any other path   a serial RS-422 adapter (setup mode, jumper W6 down)
//   COM3                           WPD/RPD's name for a serial port: /dev/ttyS2
//   sim                            a fresh in-process simulator
//   sim:FILE                       an in-process simulator whose EEPROM lives in FILE
//   eth://IP[:UDPPORT][/portP][/chN]   an SSERIAL channel of a 7I96S/7I92T
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "eth/target.hpp"
#include "link/link.hpp"
#include "link/ports.hpp"
#include "ops/core/retry.hpp"
#include "ops/core/timing.hpp"
#include "params/param_db.hpp"

namespace i20::ops {

struct Endpoint {
  enum class Kind { Serial, Sim, Eth };
  Kind kind = Kind::Sim;
  std::string text;     // as the user named it, for tables and messages
  std::string path;     // Serial: the device (COMn mapped); Sim: the EEPROM image file, may be empty
  std::string eth_url;  // Eth: the canonical eth:// URL
  std::optional<eth::EthTarget> eth;  // Eth: the URL parsed, once
  std::string line_key;               // endpoints with the same key share one physical line

  // The global options that name this endpoint, for advice lines: "--port /dev/ttyUSB0",
  // "--sim --sim-eeprom a.eeprom", "--port eth://10.0.0.2/port0/ch1".
  std::string flags() const;
  bool is_eth() const { return kind == Kind::Eth; }
  // The Ethernet target; std::logic_error for another kind (a caller's bug).
  const eth::EthTarget& eth_target() const;
};

// The forms, for help texts and error messages.
extern const char* const kEndpointForms;

// One target string. `index` makes every plain `sim` its own line. Throws UsageError.
Endpoint parse_endpoint(const std::string& text, std::size_t index = 0);

// Targets that share a line (a serial port, a simulator image, an Ethernet card) are worked
// one after another, lines side by side: the indices into `targets` per line, in order.
// Ethernet targets are left out unless `with_eth` (the fleet batches them per SSERIAL port).
std::vector<std::vector<std::size_t>> group_by_line(const std::vector<Endpoint>& targets, bool with_eth);

// The global flags: exactly one of port, sim, eth (port may be an eth:// URL or COMn).
struct TargetFlags {
  std::string port;
  bool sim = false;
  std::string sim_eeprom;
  std::string eth;  // IP[:UDPPORT] or an eth:// URL
  unsigned channel = 0;
  unsigned sserial_port = 0;
};
// nullopt when the flags name no target.
std::optional<Endpoint> endpoint_from(const TargetFlags& flags);
// The endpoint the flags name; UsageError saying how to name one when they name none.
Endpoint require_endpoint(const TargetFlags& flags);
// Every `--target`, or the global endpoint when no --target is given. Throws UsageError for
// a target given twice, for both forms at once, or for none at all.
std::vector<Endpoint> resolve_endpoints(const std::vector<std::string>& targets,
                                        const std::optional<Endpoint>& global);

struct LinkSettings {
  unsigned baud = timing::kSetupBaud;
  unsigned timeout_ms = timing::kReplyTimeoutMs;  // reply timeout on top of the wire time
  bool take_over = false;                         // Ethernet: stop a port another host (LinuxCNC) is driving
  // In-process simulator only: control lines (lib/sim/control.hpp, e.g. "busv 160") applied
  // before the first command, so --sim can stand in for a card on another supply.
  std::vector<std::string> sim_control;
};

// `i20 ports`: the serial ports with hardware behind them (USB adapters with their ids).
using link::list_ports;
using link::PortInfo;

// Opens the link. A serial port is locked for this process (flock, root included). The
// in-process simulator follows `db`, so overlays that move addresses move them on both
// sides. Throws i20::Error with advice when it cannot be opened.
std::unique_ptr<link::Link> open_link(const Endpoint& endpoint, const params::ParamDb& db,
                                      const LinkSettings& settings);
// The same with the links' options built from `retry` (ops/core/timing.hpp), the budget of the
// ops::Amp that will own the link.
std::unique_ptr<link::Link> open_link(const Endpoint& endpoint, const params::ParamDb& db,
                                      const LinkSettings& settings, const RetryPolicy& retry);

}  // namespace i20::ops
