// SPDX-License-Identifier: GPL-2.0-or-later
// Serves a virtual 8I20 on a pseudo-terminal until SIGINT/SIGTERM, taking control lines
// (see sim/control.hpp) from stdin and an optional FIFO and answering them on stdout.
#pragma once

#include <string>

#include "sim/virtual_8i20.hpp"
#include "sim/wire_model.hpp"

namespace i20::sim::app {

struct ServerOptions {
  bool read_stdin = true;
  std::string control_fifo;  // created if missing; "" for none
};

// Prints the pty's slave path alone on the first line of stdout, then serves. Returns
// the process exit code (0 after a clean SIGINT/SIGTERM).
int serve(Virtual8i20& card, WireOptions wire, const ServerOptions& options);

}  // namespace i20::sim::app
