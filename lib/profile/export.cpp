// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/export.hpp"

#include <algorithm>
#include <charconv>
#include <optional>
#include <regex>
#include <sstream>

#include "params/text.hpp"
#include "params/value.hpp"
#include "profile/error.hpp"

namespace i20::profile {
namespace {

std::uint32_t part_of(std::int64_t raw, HalPart part) {
  const auto value = static_cast<std::uint32_t>(raw);
  switch (part) {
    case HalPart::Low16: return value & 0xFFFFu;
    case HalPart::High16: return value >> 16;
    case HalPart::Whole: break;
  }
  return value;
}

const char* part_text(HalPart part) {
  switch (part) {
    case HalPart::Low16: return " (bits 0-15)";
    case HalPart::High16: return " (bits 16-31)";
    case HalPart::Whole: break;
  }
  return "";
}

void add_cell(Hostmot2Values& out, const params::Param& param, std::int64_t raw) {
  const auto names = hostmot2_names_of(param);
  if (names.empty()) {
    out.skipped.push_back(param.name + ": hostmot2 has no parameter for it; not exported");
    return;
  }
  for (const auto& n : names)
    out.settings.push_back({n.hal_name, part_of(raw, n.part), param.name, raw, n.part});
}

std::string header(const Profile& profile, const ExportOptions& options, const char* how) {
  std::ostringstream out;
  out << "# Profile " << profile.name;
  if (!options.source.empty()) out << " (" << options.source << ")";
  out << ": its EEPROM (NV) values for the 8I20 at " << options.device << ",\n"
      << "# " << how << "\n"
      << "# hostmot2 takes raw EEPROM words: voltages in 10 mV, nvmaxcurrent in 10 mA, nvrembaudrate\n"
      << "# as the baud-rate index, gains as plain numbers; a 32-bit gain is two 16-bit halves (lo, hi).\n"
      << "# NV values take effect after the 8I20 is reset or power cycled (i20tools docs/facts.md s2, s6).\n";
  return out.str();
}

std::string value_comment(const HalSetting& s, const params::ParamDb& db) {
  const params::Param& p = db.get(s.db_name);
  std::string text = "# " + s.db_name + " = " + std::to_string(s.db_raw);
  if (!p.unit.empty()) text += " (" + params::format_engineering(p, s.db_raw) + ")";
  if (s.part != HalPart::Whole) text += std::string(", this line") + part_text(s.part);
  return text + "\n";
}

std::string skipped_comments(const Hostmot2Values& values) {
  std::string text;
  for (const auto& line : values.skipped) text += "# skipped: " + line + "\n";
  return text;
}

[[noreturn]] void bad_line(std::size_t number, const std::string& reason) {
  throw Error("line " + std::to_string(number) + ": " + reason, ErrorKind::BadInput);
}

std::uint32_t parse_value(const std::string& text, std::size_t line) {
  std::uint32_t value = 0;
  const bool hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const char* begin = text.data() + (hex ? 2 : 0);
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, value, hex ? 16 : 10);
  if (ec != std::errc() || ptr != end || value > 0xFFFFu)
    bad_line(line, "'" + text + "' is not a 16-bit EEPROM word");
  return value;
}

}  // namespace

std::vector<Hostmot2Parameter> hostmot2_names_of(const params::Param& param) {
  std::vector<Hostmot2Parameter> names;
  if (!param.is_nv()) return names;
  for (const auto& a : param.aliases) names.push_back({params::lower(a.name), param.name, a.part});
  // The low half first, as the driver stores them (lower address first, little endian).
  std::stable_sort(names.begin(), names.end(), [](const auto& a, const auto& b) {
    return (a.part == HalPart::Low16) > (b.part == HalPart::Low16);
  });
  return names;
}

std::vector<Hostmot2Parameter> hostmot2_nv_parameters(const params::ParamDb& db) {
  std::vector<Hostmot2Parameter> all;
  for (const auto& p : db.all())
    for (auto& n : hostmot2_names_of(p)) all.push_back(std::move(n));
  return all;
}

void check_hal_device(std::string_view device) {
  static const std::regex by_position(R"(hm2_[a-z0-9]+\.[0-9]+\.8i20\.[0-9]+\.[0-9]+)");
  static const std::regex by_serial(R"(hm2_8i20\.[0-9a-f]{4})");
  const std::string text(device);
  if (std::regex_match(text, by_position) || std::regex_match(text, by_serial)) return;
  throw Error("--device '" + text +
                  "' is not a hostmot2 8I20 name: expected hm2_BOARD.N.8i20.PORT.CHANNEL (e.g. "
                  "hm2_7i96s.0.8i20.0.0) or hm2_8i20.XXXX (use_serial_numbers=1)",
              ErrorKind::BadInput);
}

Hostmot2Values hostmot2_values(const Profile& profile, const params::ParamDb& db) {
  Hostmot2Values out;
  for (const auto& write : cell_writes(profile, db)) {
    const params::Param& cell = db.get(write.cell);
    if (cell.is_nv())
      add_cell(out, cell, write.raw);
    else
      out.skipped.push_back(cell.name + ": a working (live) value; hostmot2 sets only EEPROM values");
  }
  if (out.settings.empty())
    throw ProfileError(profile.source, "parameters", "export",
                       "the profile sets no EEPROM value hostmot2 has a parameter for; nothing to export "
                       "(an entry needs target nv or both)");
  return out;
}

std::string hal_text(const Profile& profile, const params::ParamDb& db, const ExportOptions& options) {
  check_hal_device(options.device);
  const auto values = hostmot2_values(profile, db);
  std::string text =
      header(profile, options,
             "set from a HAL file: hostmot2 writes a changed value to the EEPROM and leaves\n"
             "# an unchanged one alone. If setp says the parameter is read-only, this hostmot2 "
             "version\n# does not write NV parameters: use `i20 profile export --setsserial`.");
  text += skipped_comments(values);
  for (const auto& s : values.settings)
    text += value_comment(s, db) + "setp " + options.device + "." + s.hal_name + " " +
            std::to_string(s.value) + "\n";
  return text;
}

std::string setsserial_text(const Profile& profile, const params::ParamDb& db, const ExportOptions& options) {
  check_hal_device(options.device);
  const auto values = hostmot2_values(profile, db);
  std::string text =
      header(profile, options,
             "written by LinuxCNC's setsserial, one EEPROM word per load. Run under halrun with\n"
             "# LinuxCNC stopped, after loading hostmot2 and the board driver as in your HAL file\n"
             "# (e.g. `loadrt hostmot2` and `loadrt hm2_eth board_ip=...`).");
  text += skipped_comments(values);
  for (const auto& s : values.settings)
    text += value_comment(s, db) + "loadrt setsserial cmd=\"set " + options.device + "." + s.hal_name + " " +
            std::to_string(s.value) + "\"\nunloadrt setsserial\n";
  return text;
}

std::map<std::string, std::int64_t> parse_exported(std::string_view text, std::string_view device,
                                                   const params::ParamDb& db) {
  static const std::regex setp(R"(^\s*setp\s+(\S+)\s+(\S+)\s*$)");
  static const std::regex setsserial(R"re(^\s*loadrt\s+setsserial\s+cmd="set\s+(\S+)\s+(\S+)"\s*$)re");
  std::map<std::string, std::int64_t> values;
  struct Halves {
    std::optional<std::int64_t> low, high;
  };
  std::map<std::string, Halves> halves;
  std::istringstream in{std::string(text)};
  std::string line;
  const std::string prefix = std::string(device) + ".";
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    std::smatch m;
    if (!std::regex_match(line, m, setp) && !std::regex_match(line, m, setsserial)) continue;
    const std::string full_name = m[1];
    if (full_name.rfind(prefix, 0) != 0) continue;
    const std::string hal_name = full_name.substr(prefix.size());
    const auto named = db.alias(hal_name);
    if (!named.alias || !named.param->is_nv())
      bad_line(number, "'" + hal_name + "' is not an 8I20 NV parameter of hostmot2");
    const std::int64_t v = parse_value(m[2], number);
    const std::string& name = named.param->name;
    switch (named.alias->part) {
      case HalPart::Whole: values[name] = v; break;
      case HalPart::Low16: halves[name].low = v; break;
      case HalPart::High16: halves[name].high = v; break;
    }
  }
  for (const auto& [name, h] : halves) {
    if (!h.low || !h.high)
      throw Error(name + " has only its " + (h.low ? "low" : "high") +
                      " 16-bit half in the text; both halves are needed to know the value",
                  ErrorKind::BadInput);
    values[name] = *h.low | (*h.high << 16);
  }
  return values;
}

}  // namespace i20::profile
