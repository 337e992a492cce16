// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/writer.hpp"

#include <cstdio>
#include <sstream>

#include "lbp/bytes.hpp"
#include "params/value.hpp"
#include "profile/quantity.hpp"

namespace i20::profile {
namespace {

// Double-quoted YAML scalar: safe for any text a user put in a name or description.
std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\x%02X", static_cast<unsigned>(static_cast<unsigned char>(c)));
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

// Multi-line notes read best as a literal block; a block cannot start with a space or
// hold control characters, so those fall back to a quoted scalar.
void write_text(std::ostringstream& out, const std::string& key, const std::string& text,
                const char* indent) {
  const bool multiline = text.find('\n') != std::string::npos;
  bool plain_lines = text.front() != ' ';
  for (const char c : text)
    if (static_cast<unsigned char>(c) < 0x20 && c != '\n') plain_lines = false;
  if (!multiline || !plain_lines) {
    out << indent << key << ": " << quoted(text) << "\n";
    return;
  }
  out << indent << key << ": |-\n";
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) out << indent << "  " << line << "\n";
}

// Engineering text when it reads back exactly (always, for the 8I20's V and A
// parameters), else raw counts, so a backup never drifts by a rounding step.
std::string value_text(const params::Param& p, std::int64_t raw) {
  const std::string text = params::format_engineering(p, raw);
  try {
    if (params::parse_value(p, text) == raw) return text;
  } catch (const params::ValueError&) {
  }
  return "{raw: " + std::to_string(raw) + "}";
}

void write_motor(std::ostringstream& out, const MotorInfo& m) {
  out << "motor:\n";
  if (!m.make.empty()) out << "  make: " << quoted(m.make) << "\n";
  if (!m.model.empty()) out << "  model: " << quoted(m.model) << "\n";
  if (m.continuous_current_a)
    out << "  continuous_current: " << format_quantity(Quantity::Current, *m.continuous_current_a) << "\n";
  if (m.peak_current_a)
    out << "  peak_current: " << format_quantity(Quantity::Current, *m.peak_current_a) << "\n";
  if (m.phase_resistance_ohm)
    out << "  phase_resistance: " << format_quantity(Quantity::Resistance, *m.phase_resistance_ohm) << "\n";
  if (m.phase_inductance_h)
    out << "  phase_inductance: " << format_quantity(Quantity::Inductance, *m.phase_inductance_h) << "\n";
  if (m.line_to_line_resistance_ohm)
    out << "  line_to_line_resistance: "
        << format_quantity(Quantity::Resistance, *m.line_to_line_resistance_ohm) << "\n";
  if (m.line_to_line_inductance_h)
    out << "  line_to_line_inductance: "
        << format_quantity(Quantity::Inductance, *m.line_to_line_inductance_h) << "\n";
  if (m.poles) out << "  poles: " << *m.poles << "\n";
}

void write_supply(std::ostringstream& out, const SupplyInfo& s) {
  out << "supply:\n";
  if (!s.description.empty()) write_text(out, "description", s.description, "  ");
  if (s.bus_voltage_v)
    out << "  bus_voltage: " << format_quantity(Quantity::Voltage, *s.bus_voltage_v) << "\n";
}

void write_origin(std::ostringstream& out, const AmpOrigin& o) {
  out << "origin:  # the 8I20 these values were read from\n";
  if (o.unit_number) out << "  unit: " << lbp::hex_value(*o.unit_number, 8) << "\n";
  if (o.firmware) out << "  firmware: " << *o.firmware << "  # SWREVISION\n";
  if (!o.card.empty()) out << "  card: " << quoted(o.card) << "\n";
}

// "  # 2.5 MBaud; guarded: ..." after an entry whose value has a meaning in the database's
// table, or whose parameter is guarded: a reader of the file sees both without the manual. The
// file names no program's option: whichever program applies it has its own way to force it.
std::string entry_comment(const params::Param& p, std::int64_t raw) {
  std::string comment = params::value_label(p, raw);
  if (!p.guard.empty())
    comment += (comment.empty() ? "" : "; ") + std::string("guarded: applying it must be forced");
  return comment.empty() ? "" : "  # " + comment;
}

void write_setting(std::ostringstream& out, const Setting& s, const params::ParamDb& db) {
  const params::Param& p = db.get(s.name);
  std::string value = value_text(p, s.raw);
  const std::string comment = entry_comment(p, s.raw);
  if (!s.target) {
    out << "  " << p.name << ": " << value << comment << "\n";
    return;
  }
  // Fold the target into the entry's map form.
  const bool raw_form = value.starts_with("{raw:");
  if (raw_form) value = value.substr(1, value.size() - 2);  // "raw: N"
  out << "  " << p.name << ": {" << (raw_form ? value : "value: " + value)
      << ", target: " << to_string(*s.target) << "}" << comment << "\n";
}

}  // namespace

std::string to_yaml(const Profile& profile, const params::ParamDb& db) {
  std::ostringstream out;
  for (const auto& comment : profile.comments) {
    std::istringstream lines(comment);
    std::string line;
    while (std::getline(lines, line)) out << "# " << line << "\n";
  }
  out << "schema: 1\n";
  out << "name: " << quoted(profile.name) << "\n";
  if (!profile.description.empty()) write_text(out, "description", profile.description, "");
  if (!profile.motor.empty()) write_motor(out, profile.motor);
  if (!profile.supply.empty()) write_supply(out, profile.supply);
  if (!profile.notes.empty()) write_text(out, "notes", profile.notes, "");
  if (!profile.origin.empty()) write_origin(out, profile.origin);
  if (profile.target) out << "target: " << to_string(*profile.target) << "\n";
  out << "parameters:\n";
  for (const auto& s : profile.settings) write_setting(out, s, db);
  return out.str();
}

}  // namespace i20::profile
