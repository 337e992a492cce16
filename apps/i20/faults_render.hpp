// SPDX-License-Identifier: GPL-2.0-or-later
// Shared by `i20 faults`, `i20 clear-faults` and `i20 watch`: reading the fault-related
// registers in one pipelined pass, telling from live readings whether a fault's cause is
// still there, and rendering lib/faults reports as text a person can act on or as JSON.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "faults/report.hpp"
#include "json.hpp"
#include "ops/diagnosis.hpp"
#include "ops/faults.hpp"
#include "ops/watch/live_readings.hpp"

namespace CLI {
class App;
}

namespace i20::cli {

struct Context;

// `i20 watch` lives in cmd_watch.cpp; register_fault_commands() registers it.
void register_watch_command(CLI::App& app, Context& ctx);

// One pass over the registers that explain a fault (lib/ops reads them, honestly).
using Readings = ops::FaultReadings;

// Whether a FAULT bit's cause is there now: lib/ops judges it from the fault table's live
// checks; the commands here only render the answer.
using ops::cause_now;
using ops::CauseNow;

// What the readings say by the fault table's data (lib/ops): bit_label, brake_on,
// live_status_report, ...
using ops::bit_label;
using ops::brake_on;
using ops::live_status_report;
using ops::live_values;
using ops::output_on;

struct RenderOptions {
  const Readings* live = nullptr;                  // adds a "now:" line per fault (cause present or gone)
  std::string clear_command = "i20 clear-faults";  // as the "now:" lines advise it, with the target
};

// The full answer for a FAULT report: title, fault output, each bit with meaning, causes
// and checks, then the register notes.
void print_fault_report(std::ostream& out, const faults::Report& report, const RenderOptions& options = {});
// STATUS bits: one line each; warnings also get their checks.
void print_status_report(std::ostream& out, const faults::Report& report);
// "Fault output (TB1 pins 5-6): OFF: ..." for a FAULT report.
std::string fault_output_text(const faults::Report& report);

// The words `i20 faults` and `i20 clear-faults` say about one bit, shared with the console
// so that the page explains a fault exactly as the commands do:
// "BUSLOVFAULT (bit 8, bus-under-voltage, maskable)": a FAULT bit's heading.
std::string fault_heading(const faults::ReportLine& line);
// The "now:" line: whether the cause is still there (from live readings) and what clears it;
// `clear` names how faults are cleared ("i20 --sim clear-faults", or the console's button).
std::string now_text(const faults::ReportLine& line, const Readings& live, const std::string& clear);
// "BUSUNDERVSTATUS (bit 3), warning, sticky, HAL pin status.bus-underv": a STATUS bit's heading.
std::string status_heading(const faults::ReportLine& line);
// Whether a STATUS bit's checks are worth showing: informational bits explain themselves.
bool status_checks_shown(const faults::ReportLine& line);
// Why a FAULT bit is still set right after CLEARFAULT; `flags` are the target's global
// options for the advice (`i20 FLAGS watch`).
std::string why_remaining(const faults::ReportLine& line, const Readings& r, const std::string& flags);

// JSON of a report: raw value, hex, title, and every set bit with all its advice; with
// live readings each FAULT bit also says whether its cause is present now.
app::Json report_json(const faults::Report& report, const Readings* live = nullptr);
app::Json line_json(const faults::ReportLine& line, const faults::Report& report,
                    const Readings* live = nullptr);
app::Json readings_json(const Readings& r);

}  // namespace i20::cli
