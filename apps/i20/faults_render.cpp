// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults_render.hpp"

#include <iostream>
#include <vector>

#include "faults/fault_table.hpp"
#include "lbp/bytes.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;

void print_list(std::ostream& out, const char* heading, const std::vector<std::string>& items,
                bool numbered) {
  if (items.empty()) return;
  out << "  " << heading << "\n";
  for (std::size_t i = 0; i < items.size(); ++i) {
    out << "    ";
    if (numbered)
      out << i + 1 << ". ";
    else
      out << "- ";
    out << items[i] << "\n";
  }
}

// "(bit 8, bus-under-voltage, maskable, masked)".
std::string bit_tags(const F::ReportLine& line) {
  std::string tags = "bit " + std::to_string(line.bit);
  if (!line.slug.empty()) tags += ", " + line.slug;
  if (line.maskable) tags += ", maskable";
  if (line.masked) tags += ", MASKED: kept off the fault output";
  return "(" + tags + ")";
}

void print_fault_line(std::ostream& out, const F::ReportLine& line, const RenderOptions& o) {
  out << "\n" << fault_heading(line) << "\n";
  // The name a LinuxCNC user sees in halshow, after hm2_<board>.<n>.8i20.<port>.<channel>.
  if (!line.linuxcnc_pin.empty()) out << "  LinuxCNC HAL pin: " << line.linuxcnc_pin << "\n";
  out << "  " << line.meaning << "\n";
  if (o.live && !line.reserved) out << "  now: " << now_text(line, *o.live, o.clear_command) << "\n";
  print_list(out, "likely causes:", line.causes, false);
  print_list(out, "check:", line.checks, true);
}

app::Json strings(const std::vector<std::string>& items) {
  auto arr = app::Json::array();
  for (const auto& s : items) arr.push(s);
  return arr;
}

app::Json optional_number(const std::optional<double>& v) {
  return v ? app::Json(*v) : app::Json();
}

app::Json cause_json(const CauseNow& c) {
  static constexpr const char* kStates[] = {"present", "gone", "unknown"};
  auto j = app::Json::object();
  j.set("state", kStates[c.state]);
  j.set("evidence", c.evidence.empty() ? app::Json() : app::Json(c.evidence));
  return j;
}

}  // namespace

std::string fault_heading(const F::ReportLine& line) {
  return (line.reserved ? "reserved bit " + std::to_string(line.bit) : line.name) + " " + bit_tags(line);
}

std::string now_text(const F::ReportLine& line, const Readings& live, const std::string& clear) {
  const CauseNow c = cause_now(line.bit, live);
  if (c.state == CauseNow::Present)
    return "cause still present: " + c.evidence + "; it cannot be cleared until that is fixed";
  if (c.state == CauseNow::Gone) return "cause gone (" + c.evidence + "): `" + clear + "` should clear it";
  if (line.clears_while_cause_persists)
    return "latched event: `" + clear + "` clears it unless it happens again at once";
  return "`" + clear + "` clears it once the cause is gone";
}

std::string status_heading(const F::ReportLine& line) {
  return bit_label(line) + ", " + std::string(F::to_string(line.severity)) + (line.sticky ? ", sticky" : "") +
         (line.linuxcnc_pin.empty() ? "" : ", HAL pin " + line.linuxcnc_pin);
}

bool status_checks_shown(const F::ReportLine& line) {
  return line.severity != F::Impact::Info;
}

std::string why_remaining(const F::ReportLine& line, const Readings& r, const std::string& flags) {
  const CauseNow c = cause_now(line.bit, r);
  if (c.state == CauseNow::Present) return "the cause is still present: " + c.evidence;
  if (c.state == CauseNow::Gone)
    return "set again at once although " + c.evidence +
           ": the condition is marginal or intermittent; watch it with `i20 " + flags + " watch`";
  if (line.reserved) return "a bit the manual does not define came back: note the value and ask Mesa";
  return "set again at once: the card still detects it, so its cause is present now";
}

std::string fault_output_text(const F::Report& report) {
  const std::string head = "Fault output (TB1 pins 5-6): ";
  if (!report.fault_output_on)
    return head +
           "depends on FAULTMASK: only maskable faults are set (give --mask VALUE, or read the card with "
           "`i20 faults`)";
  if (*report.fault_output_on) {
    if (report.value == 0) return head + "ON: no faults, the drive may run";
    return head + "ON: every set fault is masked, the fault output does not signal it";
  }
  return head + "OFF: a non-masked fault turned motor drive and the current loop off";
}

void print_fault_report(std::ostream& out, const F::Report& report, const RenderOptions& options) {
  out << report.title << "\n" << fault_output_text(report) << "\n";
  for (const auto& line : report.lines) print_fault_line(out, line, options);
  if (report.notes.empty()) return;
  out << "\nAbout FAULT:\n";
  for (const auto& n : report.notes) out << "  - " << n << "\n";
}

void print_status_report(std::ostream& out, const F::Report& report) {
  out << report.title << "\n";
  for (const auto& line : report.lines) {
    out << "  " << status_heading(line) << ": " << line.meaning << "\n";
    if (line.escalated) out << "      now: " << line.evidence << "\n";
    if (status_checks_shown(line))
      for (const auto& check : line.checks) out << "      check: " << check << "\n";
  }
}

app::Json line_json(const F::ReportLine& line, const F::Report& report, const Readings* live) {
  auto j = app::Json::object();
  j.set("bit", line.bit).set("mask", lbp::hex_value(static_cast<std::uint16_t>(1u << line.bit), 4));
  j.set("reserved", line.reserved);
  j.set("name", line.reserved ? app::Json() : app::Json(line.name));
  j.set("slug", line.reserved ? app::Json() : app::Json(line.slug));
  j.set("linuxcnc_pin", line.linuxcnc_pin.empty() ? app::Json() : app::Json(line.linuxcnc_pin));
  j.set("severity", std::string(F::to_string(line.severity))).set("meaning", line.meaning);
  j.set("causes", strings(line.causes)).set("checks", strings(line.checks));
  j.set("sticky", line.sticky).set("maskable", line.maskable);
  // For FAULT bits "masked" is unknown (null) unless FAULTMASK was given or read.
  const bool known = report.reg == F::Register::Status || report.faultmask.has_value();
  j.set("masked", known ? app::Json(line.masked) : app::Json());
  j.set("clears_while_cause_persists", line.clears_while_cause_persists).set("source", line.source);
  if (report.reg == F::Register::Status)
    j.set("escalated", line.escalated)
        .set("evidence", line.escalated ? app::Json(line.evidence) : app::Json());
  if (live && report.reg == F::Register::Fault) j.set("cause_now", cause_json(cause_now(line.bit, *live)));
  return j;
}

app::Json report_json(const F::Report& report, const Readings* live) {
  auto j = app::Json::object();
  j.set("register", std::string(F::to_string(report.reg))).set("value", report.value);
  j.set("hex", lbp::hex_value(report.value, 4)).set("title", report.title);
  if (report.reg == F::Register::Fault) {
    j.set("faultmask", report.faultmask ? app::Json(*report.faultmask) : app::Json());
    j.set("fault_output_on", report.fault_output_on ? app::Json(*report.fault_output_on) : app::Json());
  }
  auto bits = app::Json::array();
  for (const auto& line : report.lines) bits.push(line_json(line, report, live));
  j.set("bits", std::move(bits)).set("notes", strings(report.notes));
  return j;
}

app::Json readings_json(const Readings& r) {
  auto j = app::Json::object();
  j.set("busv_v", optional_number(r.busv_v)).set("temperature_c", optional_number(r.temperature_c));
  j.set("busunderv_v", optional_number(r.busunderv_v)).set("busoverv_v", optional_number(r.busoverv_v));
  j.set("brake_on", brake_on(r)).set("brakeonv_v", optional_number(r.brakeonv_v));
  // FAULT and STATUS are only ever read from confirmed addresses; the rest are named when not.
  auto not_confirmed = app::Json::array();
  for (const auto& name : r.not_confirmed) not_confirmed.push(name);
  j.set("addresses_confirmed", r.not_confirmed.empty()).set("not_confirmed", std::move(not_confirmed));
  return j;
}

}  // namespace i20::cli
