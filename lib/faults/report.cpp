// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/report.hpp"

#include <cstdio>

#include "faults/decode.hpp"
#include "faults/fault_mask.hpp"
#include "lbp/bytes.hpp"

namespace i20::faults {
namespace {

ReportLine reserved_line(Register reg, unsigned bit) {
  ReportLine line;
  line.bit = bit;
  line.reserved = true;
  line.severity = Impact::Warning;
  line.meaning = "reserved/undocumented bit " + std::to_string(bit) + " set";
  line.causes = {
      "The 8I20 manual does not define this bit: newer firmware, or a value that did not come from "
      "this card's " +
      std::string(to_string(reg)) + " register"};
  line.checks = {"Make sure the value was read from the 8I20's " + std::string(to_string(reg)) +
                     " register, not from SSLBP's CS or Interface registers",
                 "Note the raw value and SWREVISION and ask Mesa; do not assume the bit is harmless"};
  line.source = "not in the 8I20 manual's " +
                std::string(reg == Register::Fault ? "FAULT CONDITIONS" : "STATUS REGISTER") + " table";
  return line;
}

ReportLine line_for(const DecodedBit& d) {
  if (d.reserved()) return reserved_line(d.reg, d.bit);
  const BitInfo& b = *d.info;
  ReportLine line;
  line.bit = b.bit;
  line.name = b.name;
  line.slug = b.slug;
  line.linuxcnc_pin = b.linuxcnc_pin;
  line.severity = b.severity;
  line.meaning = b.meaning;
  line.causes = b.causes;
  line.checks = b.checks;
  line.sticky = b.sticky;
  line.maskable = b.maskable;
  line.clears_while_cause_persists = b.clears_while_cause_persists;
  line.source = b.source;
  return line;
}

// "FAULT 0x0102: 2 faults set: NOENABLEFAULT (bit 1), BUSLOVFAULT (bit 8, masked)".
std::string title_for(const Report& r) {
  const bool fault = r.reg == Register::Fault;
  std::string title = std::string(to_string(r.reg)) + " " + lbp::hex_value(r.value, 4);
  if (r.faultmask) title += " (FAULTMASK " + lbp::hex_value(*r.faultmask, 4) + ")";
  const auto n = r.lines.size();
  if (n == 0) return title + (fault ? ": no faults" : ": no bits set");
  title += ": " + std::to_string(n) +
           (fault ? (n == 1 ? " fault" : " faults") : (n == 1 ? " bit" : " bits")) + " set: ";
  for (std::size_t i = 0; i < n; ++i) {
    const auto& line = r.lines[i];
    title += (i ? ", " : "") + (line.reserved ? "reserved" : line.name) + " (bit " +
             std::to_string(line.bit) + (line.masked ? ", masked" : "") + ")";
  }
  return title;
}

Report build(Register reg, std::uint16_t value, const FaultTable& table) {
  Report r;
  r.reg = reg;
  r.value = value;
  for (const auto& d : decode(reg, value, table).bits) r.lines.push_back(line_for(d));
  if (value != 0) r.notes = table.notes(reg);
  return r;
}

std::string measured_text(const std::string& name, double value, const std::string& unit) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.2f", value);
  return name + " " + buf + " " + unit;
}

// The first threshold the measured value is above makes the condition hold.
void escalate(ReportLine& line, const Escalation& e, const LiveValues& live) {
  const auto measured = live.find(e.measured);
  if (measured == live.end()) return;
  for (const auto& name : e.above) {
    const auto threshold = live.find(name);
    if (threshold == live.end() || measured->second <= threshold->second) continue;
    line.escalated = true;
    line.severity = e.severity;
    line.meaning = e.meaning;
    line.checks = e.checks;
    line.evidence = measured_text(e.measured, measured->second, e.unit) + " is above " +
                    measured_text(name, threshold->second, e.unit);
    return;
  }
}

}  // namespace

Report fault_report(std::uint16_t fault, std::optional<std::uint16_t> faultmask, const FaultTable& table) {
  Report r = build(Register::Fault, fault, table);
  r.faultmask = faultmask;
  if (faultmask) {
    const MaskState state = mask_state(fault, *faultmask, table);
    for (auto& line : r.lines) line.masked = state.masked & (1u << line.bit);
    r.fault_output_on = state.fault_output_on();
  } else if ((fault & ~table.maskable_bits()) != 0 || fault == 0) {
    // Without FAULTMASK the answer is still certain unless only maskable bits are set.
    r.fault_output_on = fault == 0;
  }
  r.title = title_for(r);
  return r;
}

Report status_report(std::uint16_t status, const FaultTable& table) {
  Report r = build(Register::Status, status, table);
  r.title = title_for(r);
  return r;
}

Report status_report(std::uint16_t status, const LiveValues& live, const FaultTable& table) {
  Report r = status_report(status, table);
  for (auto& line : r.lines)
    if (const BitInfo* info = table.find(Register::Status, line.bit); info && info->escalation)
      escalate(line, *info->escalation, live);
  return r;
}

std::size_t count_at_least_warning(const Report& report) {
  std::size_t n = 0;
  for (const auto& line : report.lines) n += line.severity != Impact::Info ? 1 : 0;
  return n;
}

}  // namespace i20::faults
