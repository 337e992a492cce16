// SPDX-License-Identifier: GPL-2.0-or-later
#include "motor/loader.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>
#include <vector>

#include "motor/error.hpp"
#include "motor/units.hpp"
#include "params/closest.hpp"
#include "params/data_file.hpp"
#include "params/text.hpp"
#include "params/value.hpp"
#include "params/yaml_problem.hpp"

namespace i20::motor {
namespace {

enum class Sign { Any, NonNegative, Positive };

double quantity(Quantity kind, std::string_view text, Sign sign) {
  const double v = parse_quantity(kind, text);
  if (sign == Sign::Positive && !(v > 0)) throw MotorError(params::trim(text) + ": must be positive");
  if (sign == Sign::NonNegative && v < 0) throw MotorError(params::trim(text) + ": must not be negative");
  return v;
}

std::int64_t whole(std::string_view raw, std::int64_t lo, std::int64_t hi) {
  const std::string text = params::trim(raw);
  const auto n = params::scan_integer(text, false);
  if (n.status != params::IntegerText::Status::Ok) throw MotorError(text + ": not a whole number");
  if (n.value < lo || n.value > hi)
    throw MotorError(text + ": outside " + std::to_string(lo) + ".." + std::to_string(hi));
  return n.value;
}

bool flag(std::string_view raw) {
  const std::string text = params::trim(raw);
  if (text == "true" || text == "on" || text == "yes") return true;
  if (text == "false" || text == "off" || text == "no") return false;
  throw MotorError(text + ": expected true or false");
}

EncoderDescription& encoder(MotorParams& p) {
  if (!p.encoder) p.encoder.emplace();
  return *p.encoder;
}

HallDescription& halls(MotorParams& p) {
  if (!p.halls) p.halls.emplace();
  return *p.halls;
}

std::array<int, 3> three_inputs(std::string_view raw) {
  std::string text = params::trim(raw);
  if (text.starts_with('[') && text.ends_with(']')) text = text.substr(1, text.size() - 2);
  std::array<int, 3> out{};
  std::size_t count = 0, start = 0;
  for (;;) {
    const auto comma = text.find(',', start);
    const std::string item = params::trim(std::string_view(text).substr(start, comma - start));
    if (count == 3) throw MotorError(params::trim(raw) + ": expected three input numbers, e.g. [0, 1, 2]");
    out[count++] = static_cast<int>(whole(item, 0, 1023));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (count != 3) throw MotorError(params::trim(raw) + ": expected three input numbers, e.g. [0, 1, 2]");
  return out;
}

struct Key {
  std::string_view name;
  std::string_view form;
  std::function<void(MotorParams&, std::string_view)> set;
};

const std::vector<Key>& keys() {
  using Q = Quantity;
  static const std::vector<Key> table{
      {"name", "TEXT", [](MotorParams& p, std::string_view v) { p.name = params::trim(v); }},
      {"pole_pairs", "N",
       [](MotorParams& p, std::string_view v) { p.pole_pairs = static_cast<int>(whole(v, 1, 1000)); }},
      {"resistance", "0.6ohm",
       [](MotorParams& p, std::string_view v) {
         p.winding.resistance_ohm = quantity(Q::Resistance, v, Sign::Positive);
       }},
      {"inductance", "1.75mH",
       [](MotorParams& p, std::string_view v) {
         p.winding.inductance_h = quantity(Q::Inductance, v, Sign::Positive);
       }},
      {"torque_constant", "0.2Nm/A",
       [](MotorParams& p, std::string_view v) {
         p.torque_constant_nm_per_a = quantity(Q::TorqueConstant, v, Sign::Positive);
       }},
      {"inertia", "0.12kgcm^2",
       [](MotorParams& p, std::string_view v) { p.inertia_kgm2 = quantity(Q::Inertia, v, Sign::Positive); }},
      {"friction.viscous", "0.02mNm/(rad/s)",
       [](MotorParams& p, std::string_view v) {
         p.viscous_nm_per_rad_s = quantity(Q::Viscous, v, Sign::NonNegative);
       }},
      {"friction.coulomb", "0.01Nm",
       [](MotorParams& p, std::string_view v) { p.coulomb_nm = quantity(Q::Torque, v, Sign::NonNegative); }},
      {"cogging.torque", "0.005Nm",
       [](MotorParams& p, std::string_view v) { p.cogging_nm = quantity(Q::Torque, v, Sign::NonNegative); }},
      {"cogging.periods_per_turn", "N",
       [](MotorParams& p, std::string_view v) {
         p.cogging_periods_per_turn = static_cast<int>(whole(v, 0, 100000));
       }},
      {"load", "0.1Nm",
       [](MotorParams& p, std::string_view v) { p.load_nm = quantity(Q::Torque, v, Sign::Any); }},
      {"machine.lead", "5mm",
       [](MotorParams& p, std::string_view v) {
         p.machine.lead_m_per_turn = quantity(Q::Length, v, Sign::Positive);
       }},
      {"machine.mass", "40kg",
       [](MotorParams& p, std::string_view v) {
         p.machine.mass_kg = quantity(Q::Mass, v, Sign::NonNegative);
       }},
      {"machine.load_inertia", "2kgcm^2",
       [](MotorParams& p, std::string_view v) {
         p.machine.load_inertia_kgm2 = quantity(Q::Inertia, v, Sign::NonNegative);
       }},
      {"machine.stiffness", "800Nm/rad",
       [](MotorParams& p, std::string_view v) {
         p.machine.stiffness_nm_per_rad = quantity(Q::Stiffness, v, Sign::NonNegative);
       }},
      {"machine.damping", "0.02Nm/(rad/s)",
       [](MotorParams& p, std::string_view v) {
         p.machine.damping_nm_per_rad_s = quantity(Q::Viscous, v, Sign::NonNegative);
       }},
      {"brake.torque", "1.3Nm",
       [](MotorParams& p, std::string_view v) {
         p.brake_torque_nm = quantity(Q::Torque, v, Sign::NonNegative);
       }},
      {"brake.engaged", "true|false", [](MotorParams& p, std::string_view v) { p.brake_engaged = flag(v); }},
      {"max_speed", "6000rpm",
       [](MotorParams& p, std::string_view v) { p.max_speed_rad_s = quantity(Q::Speed, v, Sign::Positive); }},
      {"channel", "0..7",
       [](MotorParams& p, std::string_view v) { p.channel = static_cast<unsigned>(whole(v, 0, 7)); }},
      {"encoder.counts_per_turn", "N",
       [](MotorParams& p, std::string_view v) { encoder(p).counts_per_turn = whole(v, 1, 1LL << 40); }},
      {"encoder.direction", "1|-1",
       [](MotorParams& p, std::string_view v) {
         const auto d = whole(v, -1, 1);
         if (d == 0) throw MotorError("0: expected 1 or -1");
         encoder(p).direction = static_cast<int>(d);
       }},
      {"encoder.index_angle", "0deg",
       [](MotorParams& p, std::string_view v) {
         encoder(p).index_angle_rad = quantity(Q::Angle, v, Sign::Any);
       }},
      {"halls.pattern", "25",
       [](MotorParams& p, std::string_view v) {
         const auto n = static_cast<int>(whole(v, 0, 47));
         if (!known_bldc_pattern(n))
           throw MotorError(
               std::to_string(n) +
               ": only bldc's default pattern 25 is known to this tool; give halls.placement instead");
         halls(p).bldc_pattern = n;
       }},
      {"halls.placement", "120|60",
       [](MotorParams& p, std::string_view v) {
         const auto n = whole(v, 0, 360);
         if (n != 120 && n != 60) throw MotorError(params::trim(v) + ": expected 120 or 60 (degrees)");
         halls(p).placement = n == 120 ? HallPlacement::Deg120 : HallPlacement::Deg60;
       }},
      {"halls.offset", "0deg",
       [](MotorParams& p, std::string_view v) { halls(p).offset_rad = quantity(Q::Angle, v, Sign::Any); }},
      {"halls.polarity", "active-high|active-low",
       [](MotorParams& p, std::string_view v) {
         const std::string t = params::trim(v);
         if (t != "active-high" && t != "active-low")
           throw MotorError(t + ": expected active-high or active-low");
         halls(p).polarity = t == "active-high" ? HallPolarity::ActiveHigh : HallPolarity::ActiveLow;
       }},
      {"halls.inputs", "[0, 1, 2]",
       [](MotorParams& p, std::string_view v) { halls(p).inputs = three_inputs(v); }},
  };
  return table;
}

constexpr std::string_view kRequired[] = {"pole_pairs", "resistance", "inductance", "torque_constant",
                                          "inertia"};

const Key& find_key(std::string_view name) {
  const auto& table = keys();
  const auto it = std::ranges::find(table, name, &Key::name);
  if (it != table.end()) return *it;
  std::vector<params::Candidate> candidates;
  for (const auto& k : table) candidates.push_back({std::string(k.name), {std::string(k.name)}});
  const auto near = params::closest(name, candidates, 1);
  throw MotorError(
      std::string(name) + ": unknown key" +
      (near.empty() ? " (the keys: motors/README.md)" : "; did you mean '" + near.front() + "'?"));
}

struct Entry {
  std::string key;
  std::string value;
  int line = 0;
};

// The scalars of a motor file as dotted keys; a flow sequence (halls.inputs) as its text.
void flatten(const YAML::Node& node, const std::string& prefix, std::vector<Entry>& out,
             std::string_view origin) {
  const auto where = [&](const YAML::Node& n) {
    return std::string(origin) + ":" + std::to_string(n.Mark().line + 1);
  };
  if (!node.IsMap()) throw MotorError(where(node) + ": expected 'key: value' lines");
  for (const auto& item : node) {
    // A complex key (`? [a, b]`) is valid YAML but no motor key; as<string> would throw YAML's
    // own exception past the loader's contract.
    if (!item.first.IsScalar())
      throw MotorError(where(item.first) + ": a key must be a name, not a list or map");
    const std::string key = prefix + item.first.Scalar();
    const YAML::Node& value = item.second;
    if (value.IsMap()) {
      flatten(value, key + ".", out, origin);
    } else if (value.IsSequence()) {
      std::string text;
      for (const auto& element : value) {
        if (!element.IsScalar())
          throw MotorError(where(element) + ": " + key + ": expected a list of numbers");
        if (!text.empty()) text += ',';  // apart: GCC 12's -O3 -Wrestrict misfires on `"," + std::string&&`
        text += element.Scalar();
      }
      out.push_back({key, text, value.Mark().line + 1});
    } else if (value.IsScalar()) {
      out.push_back({key, value.Scalar(), value.Mark().line + 1});
    } else {
      throw MotorError(where(item.first) + ": " + key + ": has no value");
    }
  }
}

}  // namespace

void set_motor_key(MotorParams& params, std::string_view key, std::string_view value, bool live) {
  // Keys and values are printed back (errors, the motor's name in every status line), so a
  // control character is refused here, for the file and the live `motor KEY VALUE` alike.
  if (const auto c = params::control_character(key))
    throw MotorError(params::printable(key) + ": a key holds the control character " + params::escaped(*c));
  if (const auto c = params::control_character(value))
    throw MotorError(std::string(key) + ": holds the control character " + params::escaped(*c) +
                     "; remove it");
  try {
    const Key& k = find_key(key);
    if (live && key == "channel") throw MotorError("the channel of an attached motor cannot change");
    MotorParams changed = params;
    k.set(changed, value);
    params = std::move(changed);
  } catch (const MotorError& e) {
    const std::string what = e.what();
    throw MotorError(what.starts_with(std::string(key) + ":") ? what : std::string(key) + ": " + what);
  }
}

MotorParams parse_motor(std::string_view text, std::string_view origin) {
  // The loader every YAML file goes through: a second document is refused, not dropped.
  const YAML::Node root = params::load_yaml(
      text, std::string(origin),
      [](const std::string& where, const std::string& problem) { throw MotorError(where + ": " + problem); });
  if (!root.IsDefined() || root.IsNull()) throw MotorError(std::string(origin) + ": empty motor file");
  std::vector<Entry> entries;
  flatten(root, "", entries, origin);
  MotorParams params;
  std::set<std::string> seen;
  for (const auto& e : entries) {
    const std::string where = std::string(origin) + ":" + std::to_string(e.line) + ": ";
    if (!seen.insert(e.key).second) throw MotorError(where + params::printable(e.key) + ": given twice");
    try {
      set_motor_key(params, e.key, e.value);
    } catch (const MotorError& error) {
      throw MotorError(where + error.what());
    }
  }
  for (const auto key : kRequired)
    if (!seen.contains(std::string(key)))
      throw MotorError(std::string(origin) + ": " + std::string(key) + ": missing (e.g. " + std::string(key) +
                       ": " + std::string(find_key(key).form) + ")");
  if (seen.contains("halls.pattern") && (seen.contains("halls.placement") || seen.contains("halls.offset")))
    throw MotorError(std::string(origin) +
                     ": halls: give either pattern or placement (and offset), not both");
  if (params.encoder && !seen.contains("encoder.counts_per_turn"))
    throw MotorError(std::string(origin) +
                     ": encoder.counts_per_turn: missing (e.g. counts_per_turn: 10000)");
  try {
    validate(params);
  } catch (const MotorError& e) {
    throw MotorError(std::string(origin) + ": " + e.what());
  }
  return params;
}

MotorParams load_motor_file(const std::string& path) {
  const auto file = params::read_data_file(path, "motor file");
  if (!file.problem.empty()) throw MotorError(path + ": " + file.problem);
  return parse_motor(file.text, path);
}

std::string motor_keys_help() {
  std::string out;
  for (const auto& k : keys()) out += std::string(k.name) + " " + std::string(k.form) + "\n";
  return out;
}

}  // namespace i20::motor
