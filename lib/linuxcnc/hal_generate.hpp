// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal`: a complete, commented LinuxCNC HAL file for 8I20 axes on a 7I96S or 7I92T,
// written from today's hostmot2 and bldc names (docs/linuxcnc-hal.md): bldc rotor-angle to
// the 8I20's angle, a position pid whose output is the current in amps (limited to
// MAXCURRENT), and every 8I20 fault pin in the E-stop chain. Pure: returns the text.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "link/given.hpp"
#include "linuxcnc/hal_names.hpp"

namespace i20::linuxcnc {

struct HalPlan {
  std::string board = "7i96s";           // 7i96s | 7i92t
  std::string board_ip = "10.10.10.10";  // the card's IP address (hm2_eth board_ip)
  int axes = 1;                          // axis k: 8I20 on smart-serial port 0 channel k, encoder k
  std::string cfg = "qh";                // bldc cfg: qh, qhi or h
  std::optional<int> pattern;            // Hall pattern (cfg with h)
  std::optional<int> poles;              // motor poles, not pole pairs (cfg with q)
  std::optional<int> counts_per_rev;     // encoder counts per motor revolution (cfg with q)
  std::optional<int> encoder_offset;     // counts from the index to electrical zero (cfg with i)
  std::optional<double> max_current;     // the card's MAXCURRENT in amps: the pid's output limit
  std::vector<std::string> halls;        // per axis "PIN1,PIN2,PIN3" (cfg with h)
  std::string estop_in;                  // the E-stop loop's input pin; "" leaves it to the user
  bool notch = false;        // a biquad after each pid: [JOINT_k]NOTCH_N0..NOTCH_D2 (i20 pid --notch)
  std::string command_line;  // how the file was asked for, for its header
};

// The generated power-up's waits (docs/linuxcnc-hal.md, "Power-up and fault reset"), given by
// the program (ops/core/timing.hpp): how long after machine-on the smart-serial port runs, and
// how long after the port's start its 8I20s' fault pins count.
struct PowerUpDelays {
  link::Given<std::chrono::milliseconds> port_run;
  link::Given<std::chrono::milliseconds> fault_watch;
};

// The HAL device names of a board: hm2_7i96s.0, hm2_7i92.0. Throws UsageError.
std::string hm2_device(const std::string& board);

// Throws UsageError (one line, naming the option) when the plan cannot become a valid file.
void check_plan(const HalPlan& plan, const HalNames& names = HalNames::builtin());

// The HAL text. Calls check_plan first.
std::string generate_hal(const HalPlan& plan, const PowerUpDelays& delays,
                         const HalNames& names = HalNames::builtin());

}  // namespace i20::linuxcnc
