// Targets that need other layers: the in-process simulator and Ethernet cards.
#pragma once

#include <memory>
#include <string>

#include "link/link.hpp"
#include "link/pipelined_link.hpp"
#include "params/param_db.hpp"

namespace i20::app {

// The built-in simulator behind a PipelinedLink (the same framing code as a serial
// port). `eeprom_file` may be empty (EEPROM lives in memory for this run).
std::unique_ptr<link::Link> open_sim_link(const params::ParamDb& db, const std::string& eeprom_file,
                                          const link::PipelinedLinkOptions& options);

// An 8I20 behind a 7I96S/7I92T: `address` is "IP[:UDPPORT]" (with `sserial_port` and
// `channel`) or a full "eth://IP[:UDPPORT][/portP][/chN]" URL.
std::unique_ptr<link::Link> open_eth_link(const std::string& address, unsigned sserial_port, unsigned channel,
                                          unsigned timeout_ms);

}  // namespace i20::app
