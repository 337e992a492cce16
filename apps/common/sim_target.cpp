#include "sim_target.hpp"

#include "lbp/error.hpp"

namespace i20::app {

std::unique_ptr<link::Link> open_sim_link(const std::string&, const link::PipelinedLinkOptions&) {
  throw Error("the simulator link is not wired in yet");
}

std::unique_ptr<link::Link> open_eth_link(const std::string&, unsigned, unsigned) {
  throw Error("Ethernet targets are not wired in yet");
}

}  // namespace i20::app
