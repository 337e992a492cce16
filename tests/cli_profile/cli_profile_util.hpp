// SPDX-License-Identifier: GPL-2.0-or-later
// Shared by the i20 profile / tune end-to-end tests: running i20 against a simulator,
// counting what reached the EEPROM, reading --json output, and the central check of the
// fault-injection tests: what the command reported is what the card holds.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "harness.hpp"

namespace i20::test {

// A shipped profile: <source>/profiles/NAME.
std::string shipped(const std::string& name);

// Writes `text` to `path` and returns the path as a string.
std::string write_file(const std::filesystem::path& path, const std::string& text);
std::string slurp_file(const std::filesystem::path& path);

// `i20 --port PORT --no-user-params ARGS...`.
Result i20_on(const std::string& port, std::vector<std::string> args, int timeout_s = 120);

// `i20 ARGS...` started in the background with stdout and stderr going to files, so a test
// can signal it mid-run (Ctrl-C) and collect what it printed.
class Background {
 public:
  explicit Background(const std::vector<std::string>& args);
  ~Background();
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;
  void interrupt();                 // SIGINT, as Ctrl-C sends it
  Result wait(int timeout_s = 60);  // exit code and output; killed after the timeout

 private:
  int pid_ = -1;
  TempDir dir_;
};

// Data writes the simulator executed while NV access mode was on (0xEC 0x01 ... 0xEC 0x00;
// a reset or power-up leaves NV mode), i.e. EEPROM cell writes, from an i20sim trace.
std::size_t eeprom_writes(const std::string& trace);
// Every data write (RAM or EEPROM) in the trace.
std::size_t data_writes(const std::string& trace);

// Files in `dir` whose name starts with "i20-backup-".
std::vector<std::filesystem::path> backups_in(const std::filesystem::path& dir);

// The JSON document a command printed (JSON is YAML: yaml-cpp reads it).
YAML::Node json(const Result& r);

// The raw value the simulator holds for NAME (its `get` control command).
std::int64_t sim_value(SimProcess& sim, const std::string& name);

// The bus a card on the manual's 120 V line sees (the shipped line-120v profile's supply):
// the profile's 190 V brake and 195 V over-voltage are refused above the measured bus.
inline const std::vector<std::string> kLine120Bus{"--busv", "160"};

// Checks one target's apply report (the --json object) against the card's values as
// `value_of` reads them afterwards: applied -> every planned cell holds the profile's
// value; rolled back or refused -> every planned cell holds its original value;
// rollback failed -> every cell reported intended/original holds exactly that, and cells
// reported unknown are allowed anything. Reports GTest failures naming `label`.
using ValueOf = std::function<std::int64_t(const std::string& cell)>;
void expect_report_matches_card(const YAML::Node& report, const ValueOf& value_of, const std::string& label);

// The outcome a report names, and whether it is one of the four a finished apply may end
// in: applied-and-verified, nothing-to-do, rolled-back-and-verified, rollback-failed.
std::string outcome(const YAML::Node& report);

}  // namespace i20::test
