// SPDX-License-Identifier: GPL-2.0-or-later
// i20sim's command line: every switch of the simulator, with examples in --help.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "eth_server.hpp"
#include "server.hpp"
#include "sim/sim_stream.hpp"

namespace i20::sim::app {

struct Invocation {
  SimOptions sim;
  ServerOptions server;
  bool pty = false;
  bool eth = false;  // serve a virtual Ethernet card instead of a pty
  EthServeOptions eth_options;
  bool print_map = false;
  bool trace = false;
  std::vector<std::string> startup_control;  // control lines applied before serving
};

// Parses argv. Returns the exit code to use when parsing ends the run (--help, errors),
// otherwise fills `out` and returns nullopt. Messages go to stdout/stderr.
std::optional<int> parse_command_line(int argc, char** argv, Invocation& out);

}  // namespace i20::sim::app
