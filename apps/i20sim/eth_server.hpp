// SPDX-License-Identifier: GPL-2.0-or-later
// `i20sim --eth ADDR[:PORT]`: the virtual 8I20(s) behind a virtual 7I96S/7I92T on UDP,
// served until SIGINT/SIGTERM. Control lines on stdin and on the --control FIFO (created
// if missing) go to ethsim::apply_board_control (ethsim/board_control.hpp): every line of
// the simulator's language, for the first 8I20 or prefixed "ch N" / "port P ch N" / "all",
// and "host on|off" for a LinuxCNC stand-in. Answers go to stdout, as with --pty.
#pragma once

#include <string>
#include <vector>

#include "motor/params.hpp"
#include "sim/sim_stream.hpp"

namespace i20::sim::app {

struct EthServeOptions {
  std::string listen = "127.0.0.1";  // ADDR[:PORT], port 27181 by default
  std::string card = "7i96s";        // or 7i92t, 7i92t-servo
  unsigned channels = 1;             // 8I20s on port 0, channels 0..channels-1
  bool read_stdin = true;
  std::string control_fifo{};                // "" for none
  bool running_host = false;                 // start with a LinuxCNC stand-in running (host on)
  std::vector<motor::MotorParams> motors{};  // each on its `channel` of port 0 (--motor)
};

// Prints "ADDR:PORT" alone on the first line of stdout (what clients pass to --eth),
// applies `startup_control` to every 8I20, then serves. Returns the process exit code.
int serve_eth(const SimOptions& sim, const EthServeOptions& options,
              const std::vector<std::string>& startup_control = {});

}  // namespace i20::sim::app
