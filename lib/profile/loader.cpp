// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/loader.hpp"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <set>

#include "params/data_file.hpp"
#include "params/text.hpp"
#include "params/value.hpp"
#include "params/yaml_problem.hpp"
#include "profile/error.hpp"
#include "profile/quantity.hpp"

namespace i20::profile {
namespace {

using params::trim;

const std::set<std::string> kTopKeys{"schema", "name", "description", "motor", "supply", "notes", "origin",
                                     "target", "parameters",
                                     // `i20 report` files: the profile loader reads their parameters only
                                     "report"};
const std::set<std::string> kMotorKeys{"make",
                                       "model",
                                       "continuous_current",
                                       "peak_current",
                                       "phase_resistance",
                                       "phase_inductance",
                                       "line_to_line_resistance",
                                       "line_to_line_inductance",
                                       "poles",
                                       "pole_pairs"};
// A motor with more poles than this is not one an 8I20 drives (and a typo more likely).
constexpr int kMaxPoles = 200;
const std::set<std::string> kSupplyKeys{"description", "bus_voltage"};
const std::set<std::string> kEntryKeys{"value", "raw", "target"};

std::string list_of(const std::set<std::string>& keys) {
  std::string out;
  for (const auto& k : keys) out += (out.empty() ? "" : ", ") + k;
  return out;
}

// Reads YAML nodes and turns every problem into a ProfileError at the node's line.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  std::string where(const YAML::Node& at) const {
    const auto mark = at.Mark();
    return source_ + ":" + (mark.line >= 0 ? std::to_string(mark.line + 1) : std::string("?"));
  }
  int line(const YAML::Node& at) const { return at.Mark().line >= 0 ? at.Mark().line + 1 : 0; }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& rule,
                         const std::string& reason) const {
    throw ProfileError(where(at), key, rule, reason);
  }

  // A scalar's text. Control characters (an ESC that would clear a terminal, a CR) are
  // refused wherever the text may be printed; `lines` lets notes keep line breaks and tabs.
  std::string text(const YAML::Node& node, const std::string& key, bool lines = false) const {
    if (node.IsNull()) fail(node, key, "schema", "has no value");
    if (!node.IsScalar()) fail(node, key, "schema", "must be a single value, not a list or map");
    if (const auto c = params::control_character(node.Scalar(), lines))
      fail(node, key, "schema", "holds the control character " + params::escaped(*c) + "; remove it");
    return node.Scalar();
  }

  void only_keys(const YAML::Node& map, const std::set<std::string>& allowed, const std::string& what) const {
    std::set<std::string> seen;
    for (const auto& kv : map) {
      const std::string key = kv.first.Scalar();
      if (!allowed.contains(key))
        fail(kv.first, key, "schema", "unknown key in " + what + " (allowed: " + list_of(allowed) + ")");
      if (!seen.insert(key).second) fail(kv.first, key, "duplicate", "given twice in " + what);
    }
  }

  double quantity(const YAML::Node& node, const std::string& key, Quantity kind) const {
    std::string why;
    const auto value = parse_quantity(kind, text(node, key), why);
    if (!value) fail(node, key, "unit", why);
    return *value;
  }

 private:
  std::string source_;
};

// The phase (line-to-neutral) value is half the line-to-line one. Both may be given, but
// then they must agree: a data sheet's line-to-line figure typed as a phase value doubles
// the gains computed from it.
void phase_from_line_to_line(const Reader& r, const YAML::Node& node, const std::string& what,
                             const std::optional<double>& line_to_line, std::optional<double>& phase) {
  if (!line_to_line) return;
  const double half = *line_to_line / 2.0;
  if (phase && std::abs(*phase - half) > 0.01 * half)
    r.fail(node["phase_" + what], "phase_" + what, "motor",
           "is not half of line_to_line_" + what + " (give one of them, or values that agree)");
  phase = half;
}

int whole_number(const Reader& r, const YAML::Node& node, const std::string& key, int lo, int hi) {
  const std::string text = trim(r.text(node, key));
  int value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || value < lo || value > hi)
    r.fail(node, key, "motor",
           "must be a whole number from " + std::to_string(lo) + " to " + std::to_string(hi));
  return value;
}

void read_poles(const Reader& r, const YAML::Node& node, MotorInfo& motor) {
  if (node["poles"]) {
    motor.poles = whole_number(r, node["poles"], "poles", 2, kMaxPoles);
    if (*motor.poles % 2 != 0) r.fail(node["poles"], "poles", "motor", "must be even (poles come in pairs)");
  }
  if (!node["pole_pairs"]) return;
  const int pairs = whole_number(r, node["pole_pairs"], "pole_pairs", 1, kMaxPoles / 2);
  if (motor.poles && *motor.poles != 2 * pairs)
    r.fail(node["pole_pairs"], "pole_pairs", "motor", "disagrees with poles (pole_pairs is half of poles)");
  motor.poles = 2 * pairs;
}

void read_motor(const Reader& r, const YAML::Node& node, MotorInfo& motor) {
  if (!node.IsMap()) r.fail(node, "motor", "schema", "must be a map (" + list_of(kMotorKeys) + ")");
  r.only_keys(node, kMotorKeys, "motor");
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const YAML::Node& v = kv.second;
    if (key == "make") motor.make = trim(r.text(v, key));
    if (key == "model") motor.model = trim(r.text(v, key));
    if (key == "continuous_current") motor.continuous_current_a = r.quantity(v, key, Quantity::Current);
    if (key == "peak_current") motor.peak_current_a = r.quantity(v, key, Quantity::Current);
    if (key == "phase_resistance") motor.phase_resistance_ohm = r.quantity(v, key, Quantity::Resistance);
    if (key == "phase_inductance") motor.phase_inductance_h = r.quantity(v, key, Quantity::Inductance);
    if (key == "line_to_line_resistance")
      motor.line_to_line_resistance_ohm = r.quantity(v, key, Quantity::Resistance);
    if (key == "line_to_line_inductance")
      motor.line_to_line_inductance_h = r.quantity(v, key, Quantity::Inductance);
  }
  if (motor.continuous_current_a && motor.peak_current_a &&
      *motor.peak_current_a < *motor.continuous_current_a)
    r.fail(node["peak_current"], "peak_current", "motor", "is below continuous_current");
  phase_from_line_to_line(r, node, "resistance", motor.line_to_line_resistance_ohm,
                          motor.phase_resistance_ohm);
  phase_from_line_to_line(r, node, "inductance", motor.line_to_line_inductance_h, motor.phase_inductance_h);
  read_poles(r, node, motor);
}

void read_supply(const Reader& r, const YAML::Node& node, SupplyInfo& supply) {
  if (node.IsScalar()) {
    supply.description = trim(r.text(node, "supply"));
    return;
  }
  if (!node.IsMap())
    r.fail(node, "supply", "schema", "must be a description or a map (description, bus_voltage)");
  r.only_keys(node, kSupplyKeys, "supply");
  if (node["description"]) supply.description = trim(r.text(node["description"], "description"));
  if (node["bus_voltage"])
    supply.bus_voltage_v = r.quantity(node["bus_voltage"], "bus_voltage", Quantity::Voltage);
}

const std::set<std::string> kOriginKeys{"unit", "firmware", "card"};

// `origin: {unit: 0x00012345, firmware: 18, card: 8I20}`, as a save or a backup writes it.
void read_origin(const Reader& r, const YAML::Node& node, AmpOrigin& origin) {
  if (!node.IsMap()) r.fail(node, "origin", "schema", "must be a map (unit, firmware, card)");
  r.only_keys(node, kOriginKeys, "origin");
  const auto number = [&](const char* key, std::int64_t max) -> std::optional<std::int64_t> {
    if (!node[key]) return std::nullopt;
    const std::string text = r.text(node[key], key);
    const auto n = params::scan_integer(text, /*hex_suffix=*/false);
    if (n.status != params::IntegerText::Status::Ok || n.value < 0 || n.value > max)
      r.fail(
          node[key], key, "origin",
          "must be a whole number from 0 to " + std::to_string(max) + " (decimal or 0x), not '" + text + "'");
    return n.value;
  };
  if (const auto unit = number("unit", 0xFFFFFFFF)) origin.unit_number = static_cast<std::uint32_t>(*unit);
  if (const auto firmware = number("firmware", 0xFFFF))
    origin.firmware = static_cast<std::uint16_t>(*firmware);
  if (node["card"]) origin.card = trim(r.text(node["card"], "card"));
}

Memory read_target(const Reader& r, const YAML::Node& node, const std::string& key) {
  const std::string text = r.text(node, key);
  const auto target = parse_memory(text);
  if (!target) r.fail(node, key, "target", "target must be nv, working or both, not '" + text + "'");
  return *target;
}

// A parameter with a unit must say it: "750" for NVMAXCURRENT could mean 750 counts (7.5 A)
// or 750 A, and the difference is a burnt motor. The value parser refuses it as MissingUnit;
// raw counts are written "raw:750" (or as the entry {raw: 750}).
std::int64_t read_value(const Reader& r, const YAML::Node& node, const params::Param& p, bool raw) {
  const std::string text = r.text(node, p.name);
  try {
    if (raw) return params::parse_raw(p, text);
    return params::parse_value(p, text);
  } catch (const params::UnitError& e) {  // missing, unknown, or of another quantity
    r.fail(node, p.name, "unit-required", e.reason());
  } catch (const params::ValueError& e) {
    // The error line already names the entry: the reason, after the text it is about.
    std::string why = e.reason();
    if (why == e.what()) {  // a message that names the parameter itself ("... out of range for NAME")
      if (why.starts_with(p.name + ": ")) why.erase(0, p.name.size() + 2);
    } else {
      why = "'" + trim(text) + "': " + why;
    }
    r.fail(node, p.name, "value", why);
  }
}

Setting read_setting(const Reader& r, const YAML::Node& key_node, const YAML::Node& node,
                     const params::ParamDb& db) {
  const std::string key = key_node.Scalar();
  const params::Param* p = db.find(key);
  if (!p) {
    const params::UnknownParameter unknown(key, db.suggestions(key));
    r.fail(key_node, key, "unknown-parameter", unknown.what());
  }
  Setting s;
  s.name = p->name;
  s.line = r.line(key_node);
  if (node.IsMap()) {
    r.only_keys(node, kEntryKeys, "a parameter entry");
    if (!!node["value"] == !!node["raw"])
      r.fail(node, p->name, "schema", "give exactly one of value (engineering units) or raw (counts)");
    s.raw = node["raw"] ? read_value(r, node["raw"], *p, true) : read_value(r, node["value"], *p, false);
    if (node["target"]) s.target = read_target(r, node["target"], "target");
  } else {
    s.raw = read_value(r, node, *p, false);
  }
  return s;
}

void read_parameters(const Reader& r, const YAML::Node& node, const params::ParamDb& db, Profile& profile) {
  if (!node.IsMap() || node.size() == 0)
    r.fail(node, "parameters", "schema",
           "must be a map of parameter names to values, with at least one entry");
  std::set<std::string> names;
  for (const auto& kv : node) {
    Setting s = read_setting(r, kv.first, kv.second, db);
    if (!names.insert(s.name).second) r.fail(kv.first, s.name, "duplicate", "given twice");
    profile.settings.push_back(std::move(s));
  }
}

YAML::Node parse_yaml(std::string_view yaml, const std::string& source) {
  return params::load_yaml(yaml, source, [](const std::string& where, const std::string& problem) {
    throw ProfileError(where, "", "yaml", problem);
  });
}

}  // namespace

Profile load_profile_string(std::string_view yaml, const std::string& source, const params::ParamDb& db) {
  const Reader r(source);
  const YAML::Node root = parse_yaml(yaml, source);
  if (!root.IsMap())
    throw ProfileError(source + ":1", "", "schema", "a profile is a map with name and parameters");
  r.only_keys(root, kTopKeys, "a profile");
  if (root["schema"] && r.text(root["schema"], "schema") != "1")
    r.fail(root["schema"], "schema", "schema", "unsupported profile schema (this toolkit reads schema 1)");
  if (!root["name"]) r.fail(root, "name", "schema", "a profile needs a name");
  if (!root["parameters"]) r.fail(root, "parameters", "schema", "a profile needs a parameters map");

  Profile profile;
  profile.source = source;
  profile.name = trim(r.text(root["name"], "name"));
  if (profile.name.empty()) r.fail(root["name"], "name", "schema", "must not be empty");
  if (root["description"]) profile.description = trim(r.text(root["description"], "description", true));
  if (root["notes"]) profile.notes = trim(r.text(root["notes"], "notes", true));
  if (root["motor"]) read_motor(r, root["motor"], profile.motor);
  if (root["supply"]) read_supply(r, root["supply"], profile.supply);
  if (root["origin"]) read_origin(r, root["origin"], profile.origin);
  if (root["target"]) profile.target = read_target(r, root["target"], "target");
  read_parameters(r, root["parameters"], db, profile);
  (void)cell_writes(profile, db);  // targets resolvable, no cell written twice
  return profile;
}

Profile load_profile_file(const std::filesystem::path& path, const params::ParamDb& db) {
  const auto file = params::read_data_file(path, "profile");
  if (!file.problem.empty()) throw ProfileError(path.string(), "", "file", file.problem);
  return load_profile_string(file.text, path.string(), db);
}

}  // namespace i20::profile
