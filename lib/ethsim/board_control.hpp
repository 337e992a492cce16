// SPDX-License-Identifier: GPL-2.0-or-later
// The simulator's control language with a virtual Ethernet card (i20sim --eth): every
// line of sim/control.hpp, addressed to one 8I20 or to all of them, plus lines for the
// card itself. One line in, one answer out.
//
//   LINE                          the first 8I20 (port 0 channel 0 unless it has none)
//   ch N LINE | channel N LINE    the 8I20 on channel N of SSERIAL port 0, e.g. "ch 2 busv 24"
//   port P ch N LINE              the 8I20 on port P channel N (7I92T)
//   all LINE                      every 8I20; the answers joined by "; "
//   amplifiers                    which channels have an 8I20
//   host on [PERIOD_MS] [port P]  another host starts running the machine in normal mode
//                                 (a LinuxCNC stand-in: simulated_host.hpp), default 1 ms
//   host off                      that host exits (it stops its port)
//   host                          what the host is doing
//   card reset [MS]               the card resets (silent MS ms, SSERIAL ports stopped after)
//   card power-loss MS            the card and its 8I20s lose power for MS ms
#pragma once

#include <string>
#include <string_view>

#include "ethsim/server.hpp"

namespace i20::ethsim {

// Applies `line` at the current time. Throws sim::ControlError (a one-line reason and the
// expected form) for anything it does not understand. Blank lines and # comments: "".
std::string apply_board_control(BoardServer& server, std::string_view line);

// The card-level forms above, one per line, for --help and "help".
std::string board_control_help();

}  // namespace i20::ethsim
