// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal lint --load`: the files run in LinuxCNC's halrun against a virtual 7I96S/7I92T,
// so that every name hostmot2, bldc and the other components do not create becomes a
// finding on its line. Pure: the plan (which virtual card, which lines cannot load outside
// a running LinuxCNC) and the reading of halcmd's messages; the app runs halrun.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "linuxcnc/hal_file.hpp"
#include "linuxcnc/hal_lint.hpp"

namespace i20::linuxcnc {

// One file as given, and its statements (read_hal).
struct HalSource {
  std::string file;
  std::string text;
  std::vector<Statement> statements;
};

// The virtual card the files need.
struct VirtualBoardNeed {
  std::string card = "7i96s";  // i20sim --card: 7i96s | 7i92t-servo
  std::string board_ip;        // hm2_eth's board_ip
  int channels = 1;            // 8I20s on smart-serial port 0
  bool motion = false;         // motmod is loaded: LinuxCNC 2.9 loads homemod and tpmod first
  bool ini = false;            // the files read INI values ([SECTION]KEY)
};

struct LoadPlan {
  VirtualBoardNeed need;
  // Per file: its text with the statements that cannot load outside a running LinuxCNC
  // commented out, line for line, so halcmd's line numbers are the file's.
  std::vector<std::string> loadable;
  // "FILE:LINE: why", for each statement left out.
  std::vector<std::string> left_out;
};

// Throws UsageError when the files load no hm2_eth board (--load runs them against a
// virtual Ethernet card only) or name no board address.
LoadPlan plan_load(const std::vector<HalSource>& sources);

// halcmd's "PATH:LINE: message" lines (halrun -k reports every failing command) as
// findings on the files the copies stand for. `copies` maps a copy's path to its file.
// Lines of no copy are returned in `other` (hm2_eth's own complaints, say).
struct HalrunReading {
  std::vector<LintFinding> findings;
  std::vector<std::string> other;
  bool realtime_failed = false;  // LinuxCNC's rtapi_app did not start: no file was judged
  // When it did not: the first line naming rtapi_app and the lines just before it, which say
  // why (hm2_eth's own complaint); the unloading that follows says nothing.
  std::vector<std::string> realtime_why;
};
HalrunReading read_halrun_output(std::string_view output, const std::map<std::string, std::string>& copies);

// Adds halcmd's findings from a load to the lint's own: one line, one finding. A line the
// lint already found halcmd refuses by its own rules (an INI key missing, a pin on two
// signals) is not reported again in halcmd's words; the rest are added.
void add_halrun_findings(std::vector<LintFinding>& findings, const std::vector<LintFinding>& from_halrun);

}  // namespace i20::linuxcnc
