// `i20sim --eth ADDR[:PORT]`: the virtual 8I20(s) behind a virtual 7I96S/7I92T on UDP,
// served until SIGINT/SIGTERM. Control lines on stdin act on the first 8I20 (port 0,
// channel 0) and are answered on stdout, as with --pty.
#pragma once

#include <string>

#include "sim/sim_stream.hpp"

namespace i20::sim::app {

struct EthServeOptions {
  std::string listen = "127.0.0.1";  // ADDR[:PORT], port 27181 by default
  std::string card = "7i96s";        // or 7i92t
  unsigned channels = 1;             // 8I20s on port 0, channels 0..channels-1
  bool read_stdin = true;
};

// Prints "ADDR:PORT" alone on the first line of stdout (what clients pass to --eth),
// then serves. Returns the process exit code.
int serve_eth(const SimOptions& sim, const EthServeOptions& options);

}  // namespace i20::sim::app
