// SPDX-License-Identifier: GPL-2.0-or-later
// A structured answer to "why did the axis drop out, and what do I check?".
//
// Plain data for the apps to render as text or JSON: a title line, one line per set bit
// with its causes and checks, and the register-wide notes. No formatting happens here.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "faults/fault_table.hpp"

namespace i20::faults {

struct ReportLine {
  unsigned bit = 0;
  bool reserved = false;  // the manual defines no such bit; name and slug are empty
  std::string name;
  std::string slug;
  std::string linuxcnc_pin;
  Impact severity = Impact::Fault;
  std::string meaning;
  std::vector<std::string> causes;
  std::vector<std::string> checks;
  bool sticky = false;
  bool maskable = false;
  bool masked = false;  // FAULTMASK keeps it off the fault output (known only with FAULTMASK)
  bool clears_while_cause_persists = false;
  std::string source;
  // The bit's `escalate` condition holds on the live values given: severity, meaning and
  // checks are the escalation's, and `evidence` says what was measured.
  bool escalated = false;
  std::string evidence;  // "BUSV 320.00 V is above BRAKEONV 190.00 V"
};

// Live values by parameter name (engineering units) that `escalate` conditions compare;
// a missing name is unknown, and a condition on an unknown value does not hold.
using LiveValues = std::map<std::string, double>;

struct Report {
  Register reg = Register::Fault;
  std::uint16_t value = 0;
  std::optional<std::uint16_t> faultmask;  // FAULT reports given a FAULTMASK reading
  // FAULT reports: whether the fault output (TB1 5/6) is on; empty if it depends on a
  // FAULTMASK that was not given. Always empty for STATUS reports.
  std::optional<bool> fault_output_on;
  std::string title;               // e.g. "FAULT 0x0102: 2 faults set: NOENABLEFAULT (bit 1), ..."
  std::vector<ReportLine> lines;   // set bits, lowest first
  std::vector<std::string> notes;  // register-wide advice, present when anything is set
};

Report fault_report(std::uint16_t fault, std::optional<std::uint16_t> faultmask = std::nullopt,
                    const FaultTable& table = FaultTable::builtin());
Report status_report(std::uint16_t status, const FaultTable& table = FaultTable::builtin());
// The same, with each set bit's escalation judged on `live`.
Report status_report(std::uint16_t status, const LiveValues& live, const FaultTable& table = FaultTable::builtin());
// Set bits of a report whose severity is Warning or Fault (the STATUS ones a person must act on).
std::size_t count_at_least_warning(const Report& report);

}  // namespace i20::faults
