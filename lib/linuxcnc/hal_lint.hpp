// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal lint`: the mistakes that reach a LinuxCNC 8I20 configuration from old sample
// configs and from PnCconf (docs/linuxcnc-hal.md lists every rule and its source). Pure:
// it judges statements read by read_hal, all files of one configuration together.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "linuxcnc/hal_file.hpp"
#include "linuxcnc/hal_names.hpp"

namespace i20::linuxcnc {

enum class LintSeverity { Error, Warning };

struct LintFinding {
  SourceLine at;
  LintSeverity severity = LintSeverity::Error;
  std::string rule;     // short id: obsolete-8i20-name, second-lead, ...
  std::string message;  // what is wrong, one sentence
  std::string fix;      // what to write instead
  // halcmd refuses the statement by its own rules, whatever the components are (a module
  // loaded twice, a pin on two signals, two writers or two types on one signal, setp of a
  // linked pin or an output): the file does not load. Exit 2, as a syntax error is.
  bool refused_by_halcmd = false;
};

struct LintOptions {
  // The card's MAXCURRENT in amps, when known: a current command that can exceed it is
  // reported (pid maxoutput, the 8I20 current limits).
  std::optional<double> max_current;
  // The Hall pattern commissioning found: every bldc instance with Halls must use it.
  std::optional<int> pattern;
};

// Findings in the order of the files and lines they point at (files in the order given).
std::vector<LintFinding> lint(const std::vector<Statement>& statements, const LintOptions& options,
                              const HalNames& names = HalNames::builtin());

// `i20 hal lint`'s exit code for these findings: 0 none, 1 findings, 2 a statement halcmd
// refuses (refused_by_halcmd).
int lint_exit_code(const std::vector<LintFinding>& findings);

// "FILE:LINE: error: MESSAGE (fix: FIX)".
std::string to_string(const LintFinding& finding);

}  // namespace i20::linuxcnc
