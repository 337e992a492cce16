// SPDX-License-Identifier: GPL-2.0-or-later
// Strict loader of params/faults.yaml. Every rejection names file and line.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "faults/fault_table.hpp"
#include "params/data_file.hpp"
#include "params/yaml_problem.hpp"

namespace i20::faults {
namespace {

const std::set<std::string> kTopKeys{"schema", "device", "notes", "fault", "status"};
const std::set<std::string> kNoteKeys{"fault", "status"};
const std::set<std::string> kBitKeys{"bit",
                                     "name",
                                     "slug",
                                     "linuxcnc_pin",
                                     "severity",
                                     "meaning",
                                     "causes",
                                     "checks",
                                     "sticky",
                                     "maskable",
                                     "clears_while_cause_persists",
                                     "source",
                                     "escalate",
                                     "live_check"};
const std::set<std::string> kEscalateKeys{"measured", "above", "unit", "severity", "meaning", "checks"};
const std::set<std::string> kLiveCheckKeys{"measured", "above",  "below",      "unit",        "fixed",
                                           "advice",   "status", "status_set", "status_clear"};

std::string join(const std::set<std::string>& words) {
  std::string out;
  for (const auto& w : words) out += (out.empty() ? "" : ", ") + w;
  return out;
}

bool all_of_chars(std::string_view s, bool (*ok)(char)) {
  return !s.empty() && std::all_of(s.begin(), s.end(), ok);
}
bool slug_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-';
}
bool name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}
bool pin_char(char c) {
  return std::isgraph(static_cast<unsigned char>(c)) != 0;
}

// Reads YAML nodes and annotates every error with file and line.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& reason) const {
    throw FaultFileError(where(at) + ": " + reason);
  }
  std::string where(const YAML::Node& at) const {
    const auto line = at.Mark().line;
    return source_ + ":" + (line >= 0 ? std::to_string(line + 1) : std::string("?"));
  }

  std::string text(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar() || node.Scalar().empty()) fail(node, "'" + key + "' must be a non-empty text");
    return node.Scalar();
  }

  bool boolean(const YAML::Node& node, const std::string& key) const {
    const std::string s = node.IsScalar() ? node.Scalar() : "";
    if (s == "true") return true;
    if (s == "false") return false;
    fail(node, "'" + key + "' must be true or false, not '" + s + "'");
  }

  // A register bit: a whole number 0..15.
  unsigned bit(const YAML::Node& node) const {
    const std::string s = node.IsScalar() ? node.Scalar() : "";
    int value = -1;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
    if (s.empty() || ec != std::errc() || ptr != s.data() + s.size())
      fail(node, "'bit' must be a whole number 0..15, not '" + s + "'");
    if (value < 0 || value > 15) fail(node, "bit " + s + " is outside the 16-bit register (bits 0..15)");
    return static_cast<unsigned>(value);
  }

  // A list of non-empty texts; an empty list is refused because advice is the point.
  std::vector<std::string> texts(const YAML::Node& node, const std::string& key) const {
    if (!node.IsSequence() || node.size() == 0) fail(node, "'" + key + "' must be a non-empty list of texts");
    std::vector<std::string> out;
    for (const auto& item : node) out.push_back(text(item, key));
    return out;
  }

  // Refuses keys outside `allowed` and keys given twice (yaml-cpp keeps both silently).
  void only_keys(const YAML::Node& map, const std::set<std::string>& allowed, const std::string& what) const {
    std::set<std::string> seen;
    for (const auto& kv : map) {
      const auto key = kv.first.Scalar();
      if (!allowed.contains(key))
        fail(kv.first, "unknown key '" + key + "' in " + what + " (allowed: " + join(allowed) + ")");
      if (!seen.insert(key).second) fail(kv.first, "key '" + key + "' given twice in " + what);
    }
  }

  void require(const YAML::Node& map, const std::string& key, const std::string& what) const {
    if (!map[key]) fail(map, what + " lacks required key '" + key + "'");
  }

 private:
  std::string source_;
};

Impact severity(const Reader& r, const YAML::Node& node) {
  const auto s = r.text(node, "severity");
  if (s == "fault") return Impact::Fault;
  if (s == "warning") return Impact::Warning;
  if (s == "info") return Impact::Info;
  r.fail(node, "'severity' must be fault, warning or info, not '" + s + "'");
}

bool parameter_name(const std::string& s) {
  return all_of_chars(s, name_char);
}

Escalation read_escalation(const Reader& r, const YAML::Node& node, const std::string& what) {
  const std::string where = "the 'escalate' block of " + what;
  if (!node.IsMap()) r.fail(node, "'escalate' must be a map of keys");
  r.only_keys(node, kEscalateKeys, where);
  for (const auto& key : kEscalateKeys) r.require(node, key, where);
  Escalation e;
  e.measured = r.text(node["measured"], "measured");
  if (!parameter_name(e.measured)) r.fail(node["measured"], "'measured' must be a parameter name like BUSV");
  e.above = r.texts(node["above"], "above");
  for (const auto& name : e.above)
    if (!parameter_name(name)) r.fail(node["above"], "'above' must list parameter names, not '" + name + "'");
  e.unit = r.text(node["unit"], "unit");
  e.severity = severity(r, node["severity"]);
  e.meaning = r.text(node["meaning"], "meaning");
  e.checks = r.texts(node["checks"], "checks");
  return e;
}

// A fixed limit: a finite decimal number, e.g. 85 or 400.
std::optional<double> number(const std::string& s) {
  double value = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

LiveCheck read_live_check(const Reader& r, const YAML::Node& node, const std::string& what) {
  const std::string where = "the 'live_check' block of " + what;
  if (!node.IsMap()) r.fail(node, "'live_check' must be a map of keys");
  r.only_keys(node, kLiveCheckKeys, where);
  LiveCheck c;
  c.origin = r.where(node);
  if (!node["measured"] && !node["status"])
    r.fail(node,
           where + " needs 'measured' (a reading and its threshold) or 'status' (a STATUS bit), or both");
  if (node["measured"]) {
    c.measured = r.text(node["measured"], "measured");
    if (!parameter_name(c.measured))
      r.fail(node["measured"], "'measured' must be a parameter name like BUSV");
    if (node["above"].IsDefined() == node["below"].IsDefined())
      r.fail(node, where + " needs exactly one of 'above' and 'below' with 'measured'");
    const bool above = node["above"].IsDefined();
    const auto key = above ? "above" : "below";
    c.compare = above ? LiveCheck::Compare::Above : LiveCheck::Compare::Below;
    const std::string threshold = r.text(node[key], key);
    if (const auto value = number(threshold))
      c.threshold_value = value;
    else if (parameter_name(threshold))
      c.threshold_param = threshold;
    else
      r.fail(node[key], std::string("'") + key +
                            "' must be a parameter name like BUSOVERV or a number, not '" + threshold + "'");
    r.require(node, "unit", where);
    c.unit = r.text(node["unit"], "unit");
    if (node["fixed"]) {
      c.fixed = r.boolean(node["fixed"], "fixed");
      if (c.fixed && !c.threshold_value)
        r.fail(node["fixed"], "'fixed: true' is for a number (a limit of the card), not a parameter");
    }
    if (node["advice"]) c.advice = r.text(node["advice"], "advice");
  } else {
    for (const auto* key : {"above", "below", "unit", "fixed", "advice"})
      if (node[key]) r.fail(node[key], std::string("'") + key + "' needs 'measured' in " + where);
  }
  if (node["status"]) {
    c.status_slug = r.text(node["status"], "status");
    r.require(node, "status_set", where);
    c.status_set = r.text(node["status_set"], "status_set");
    if (node["status_clear"]) c.status_clear = r.text(node["status_clear"], "status_clear");
  } else {
    for (const auto* key : {"status_set", "status_clear"})
      if (node[key]) r.fail(node[key], std::string("'") + key + "' needs 'status' in " + where);
  }
  return c;
}

// A live check's `status` names a STATUS bit by slug; known only once both registers are read.
void resolve_status_bits(std::vector<BitInfo>& fault, const std::vector<BitInfo>& status) {
  for (auto& b : fault) {
    if (!b.live_check || b.live_check->status_slug.empty()) continue;
    auto& c = *b.live_check;
    const auto it = std::ranges::find(status, c.status_slug, &BitInfo::slug);
    if (it == status.end())
      throw FaultFileError(c.origin + ": 'status' of FAULT bit " + std::to_string(b.bit) +
                           "'s live_check names no STATUS bit: '" + c.status_slug +
                           "' (give a STATUS bit's slug, e.g. status-no-enable)");
    c.status_bit = it->bit;
  }
}

BitInfo read_bit(const Reader& r, const YAML::Node& entry, Register reg) {
  const std::string what = "a " + std::string(to_string(reg)) + " bit";
  if (!entry.IsMap()) r.fail(entry, "each bit must be a map of keys");
  r.only_keys(entry, kBitKeys, what);
  for (const auto& key : kBitKeys)
    if (key != "linuxcnc_pin" && key != "escalate" && key != "live_check") r.require(entry, key, what);

  BitInfo b;
  b.reg = reg;
  b.bit = r.bit(entry["bit"]);
  b.name = r.text(entry["name"], "name");
  if (!all_of_chars(b.name, name_char))
    r.fail(entry["name"],
           "'name' must be upper case letters, digits or _ like the manual's, not '" + b.name + "'");
  b.slug = r.text(entry["slug"], "slug");
  if (!all_of_chars(b.slug, slug_char) || !std::isalpha(static_cast<unsigned char>(b.slug[0])))
    r.fail(entry["slug"],
           "'slug' must be lower case letters, digits and -, starting with a letter, not '" + b.slug + "'");
  if (entry["linuxcnc_pin"]) {
    b.linuxcnc_pin = r.text(entry["linuxcnc_pin"], "linuxcnc_pin");
    if (!all_of_chars(b.linuxcnc_pin, pin_char)) r.fail(entry["linuxcnc_pin"], "'linuxcnc_pin' has blanks");
    // hostmot2 names each bit after its register (sserial.h hm2_8i20_params): fault.x, status.x.
    const std::string prefix = reg == Register::Fault ? "fault." : "status.";
    std::string head = b.linuxcnc_pin.substr(0, prefix.size());
    for (auto& c : head) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (head != prefix || b.linuxcnc_pin.size() == prefix.size())
      r.fail(entry["linuxcnc_pin"], "'linuxcnc_pin' of a " + std::string(to_string(reg)) + " bit must be " +
                                        prefix + "NAME, not '" + b.linuxcnc_pin + "'");
  }
  b.severity = severity(r, entry["severity"]);
  b.meaning = r.text(entry["meaning"], "meaning");
  b.causes = r.texts(entry["causes"], "causes");
  b.checks = r.texts(entry["checks"], "checks");
  b.sticky = r.boolean(entry["sticky"], "sticky");
  b.maskable = r.boolean(entry["maskable"], "maskable");
  if (b.maskable && reg != Register::Fault)
    r.fail(entry["maskable"], "only FAULT bits can be maskable (FAULTMASK covers the FAULT register)");
  b.clears_while_cause_persists =
      r.boolean(entry["clears_while_cause_persists"], "clears_while_cause_persists");
  b.source = r.text(entry["source"], "source");
  b.origin = r.where(entry);
  if (entry["escalate"]) b.escalation = read_escalation(r, entry["escalate"], what);
  if (entry["live_check"]) {
    if (reg != Register::Fault)
      r.fail(entry["live_check"], "'live_check' is for FAULT bits (a STATUS bit shows its condition itself)");
    b.live_check = read_live_check(r, entry["live_check"], what);
  }
  return b;
}

// Names, slugs and pins are looked up across both registers, so they must be unique
// across both (a bit may reuse its own spelling: name MODULE, slug module); bits only
// within their register.
class Uniqueness {
 public:
  explicit Uniqueness(const Reader& r) : r_(r) {}

  void check(const YAML::Node& entry, const BitInfo& b) {
    const auto owner = std::string(to_string(b.reg)) + " bit " + std::to_string(b.bit);
    if (const auto [it, fresh] = bits_.emplace(owner, r_.where(entry["bit"])); !fresh)
      r_.fail(entry["bit"], "duplicate " + owner + " (first at " + it->second + ")");
    claim(lower(b.name), owner, entry["name"], "duplicate name '" + b.name + "'");
    claim(lower(b.slug), owner, entry["slug"], "duplicate slug '" + b.slug + "'");
    if (!b.linuxcnc_pin.empty())
      claim(lower(b.linuxcnc_pin), owner, entry["linuxcnc_pin"],
            "duplicate linuxcnc_pin '" + b.linuxcnc_pin + "'");
  }

 private:
  struct Claim {
    std::string owner;
    std::string where;
  };

  static std::string lower(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  }
  void claim(const std::string& key, const std::string& owner, const YAML::Node& at,
             const std::string& reason) {
    const auto [it, fresh] = taken_.emplace(key, Claim{owner, r_.where(at)});
    if (!fresh && it->second.owner != owner) r_.fail(at, reason + " (first at " + it->second.where + ")");
  }

  const Reader& r_;
  std::map<std::string, std::string> bits_;  // "FAULT bit 3" -> where
  std::map<std::string, Claim> taken_;       // lower-case name, slug or pin -> its bit
};

std::vector<BitInfo> read_register(const Reader& r, const YAML::Node& root, Register reg,
                                   Uniqueness& unique) {
  const std::string key = reg == Register::Fault ? "fault" : "status";
  const auto list = root[key];
  if (!list || !list.IsSequence() || list.size() == 0)
    r.fail(list ? list : root, "'" + key + "' must be a non-empty list of bits");
  std::vector<BitInfo> out;
  for (const auto& entry : list) {
    out.push_back(read_bit(r, entry, reg));
    unique.check(entry, out.back());
  }
  std::ranges::sort(out, {}, &BitInfo::bit);
  return out;
}

std::vector<std::string> read_notes(const Reader& r, const YAML::Node& root, const std::string& key) {
  const auto notes = root["notes"];
  if (!notes) return {};
  if (!notes.IsMap()) r.fail(notes, "'notes' must be a map {fault: [...], status: [...]}");
  r.only_keys(notes, kNoteKeys, "notes");
  return notes[key] ? r.texts(notes[key], "notes." + key) : std::vector<std::string>{};
}

YAML::Node parse_yaml(std::string_view yaml, const std::string& source) {
  return params::load_yaml(yaml, source, [](const std::string& where, const std::string& problem) {
    throw FaultFileError(where + ": " + problem);
  });
}

}  // namespace

FaultTable FaultTable::load_file(const std::filesystem::path& path) {
  const auto file = params::read_data_file(path, "fault table");
  if (!file.problem.empty()) throw FaultFileError(path.string() + ": " + file.problem);
  return load_string(file.text, path.string());
}

FaultTable FaultTable::load_string(std::string_view yaml, const std::string& source_name) {
  const Reader r(source_name);
  const auto root = parse_yaml(yaml, source_name);
  if (!root.IsMap()) throw FaultFileError(source_name + ":1: expected a map with 'fault' and 'status' lists");
  r.only_keys(root, kTopKeys, "the fault table");
  if (!root["schema"] || r.text(root["schema"], "schema") != "1")
    r.fail(root["schema"] ? root["schema"] : root, "'schema: 1' is required (this toolkit reads schema 1)");
  if (root["device"] && r.text(root["device"], "device") != "8I20")
    r.fail(root["device"], "this table is for device '" + root["device"].Scalar() + "', not the 8I20");

  FaultTable table;
  Uniqueness unique(r);
  table.fault_ = read_register(r, root, Register::Fault, unique);
  table.status_ = read_register(r, root, Register::Status, unique);
  resolve_status_bits(table.fault_, table.status_);
  table.fault_notes_ = read_notes(r, root, "fault");
  table.status_notes_ = read_notes(r, root, "status");
  table.source_ = source_name;
  return table;
}

}  // namespace i20::faults
