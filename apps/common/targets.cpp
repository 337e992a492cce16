#include "targets.hpp"

#include "eth/passthrough_link.hpp"
#include "eth/target.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"

namespace i20::app {

std::unique_ptr<link::Link> open_sim_link(const params::ParamDb& db, const std::string& eeprom_file,
                                          const link::PipelinedLinkOptions& options) {
  sim::SimOptions sim;
  // The simulated card follows the same database the tool uses, so --params overlays
  // that move addresses move them on both sides.
  sim.device.map = sim::register_map_from(db);
  if (!eeprom_file.empty()) sim.device.eeprom_file = eeprom_file;
  sim.name = "the built-in simulator";
  return sim::make_sim_link(std::move(sim), options);
}

std::unique_ptr<link::Link> open_eth_link(const std::string& address, unsigned sserial_port, unsigned channel,
                                          unsigned timeout_ms) {
  const auto target = eth::is_eth_url(address) ? eth::parse_target(address)
                                               : eth::make_target(address, channel, sserial_port);
  eth::PassthroughOptions options;
  options.udp.timeout = std::chrono::milliseconds(timeout_ms);
  return eth::SslbpPassthroughLink::open(target, options);
}

}  // namespace i20::app
