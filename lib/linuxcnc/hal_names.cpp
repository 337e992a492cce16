// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_names.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <set>

#include "error/error.hpp"
#include "faults/fault_table.hpp"
#include "params/yaml_problem.hpp"

namespace i20::linuxcnc {
namespace {

[[noreturn]] void reject(const std::string& source, const YAML::Node& node, const std::string& problem) {
  // Appended apart: GCC 12's -O3 -Wrestrict misfires on `":" + std::string&&`.
  std::string where = source;
  if (!node.Mark().is_null()) {
    where += ':';
    where += std::to_string(node.Mark().line + 1);
  }
  throw UsageError(where + ": " + problem);
}

YAML::Node required(const std::string& source, const YAML::Node& parent, const char* key) {
  const auto node = parent[key];
  if (!node) reject(source, parent, std::string("missing key '") + key + "'");
  return node;
}

std::vector<std::string> strings(const std::string& source, const YAML::Node& node) {
  if (!node) return {};
  if (!node.IsSequence()) reject(source, node, "expected a list of names");
  std::vector<std::string> out;
  for (const auto& item : node) out.push_back(item.as<std::string>());
  return out;
}

std::string letters(const std::string& source, const YAML::Node& node) {
  std::string out;
  for (const auto& letter : strings(source, node)) {
    if (letter.size() != 1) reject(source, node, "a cfg letter is one character: '" + letter + "'");
    out += letter;
  }
  return out;
}

// "float in", "u32 ro": a HAL type and a direction, as halcmd's `show` lists them.
HalObject hal_object(const std::string& source, const YAML::Node& node) {
  const auto text = node.as<std::string>();
  const auto space = text.find(' ');
  HalObject o{text.substr(0, space), space == std::string::npos ? "" : text.substr(space + 1)};
  const std::set<std::string> types{"bit", "float", "s32", "u32"};
  const std::set<std::string> directions{"in", "out", "io", "rw", "ro"};
  if (types.count(o.type) == 0 || directions.count(o.direction) == 0)
    reject(source, node, "'" + text + "' is not 'TYPE DIRECTION' (bit|float|s32|u32, in|out|io|rw|ro)");
  return o;
}

// A map of names to "TYPE DIRECTION"; `params` requires rw/ro, else in/out/io.
HalObjects hal_objects(const std::string& source, const YAML::Node& node, bool params) {
  HalObjects out;
  if (!node) return out;
  if (!node.IsMap()) reject(source, node, "expected names with 'TYPE DIRECTION'");
  for (const auto& item : node) {
    auto o = hal_object(source, item.second);
    if (o.is_param() != params)
      reject(source, item.second,
             item.first.as<std::string>() + ": a " + (params ? "param" : "pin") + " is " +
                 (params ? "rw or ro" : "in, out or io"));
    out[item.first.as<std::string>()] = std::move(o);
  }
  return out;
}

// hostmot2's 8I20 table: the inputs and outputs with their params, the card's read-only
// globals and the fault/status bits with their twins.
HalObjects i20_table(const std::vector<std::string>& inputs, const std::vector<std::string>& input_params,
                     const std::vector<std::string>& outputs, const std::vector<std::string>& output_params,
                     const std::vector<std::string>& globals, const std::vector<std::string>& bits,
                     const std::string& twin_suffix) {
  HalObjects out;
  const auto add_value = [&](const std::string& name, const char* direction,
                             const std::vector<std::string>& params) {
    out[name] = {"float", direction};
    for (const auto& p : params) out[name + "-" + p] = {"float", "rw"};
  };
  for (const auto& name : inputs) add_value(name, "in", input_params);
  for (const auto& name : outputs) add_value(name, "out", output_params);
  for (const auto& name : globals) out[name] = {"u32", "ro"};
  for (const auto& bit : bits) {
    out[bit] = {"bit", "out"};
    out[bit + twin_suffix] = {"bit", "out"};
  }
  return out;
}

bool has_any(std::string_view cfg, std::string_view set) {
  return cfg.find_first_of(set) != std::string_view::npos;
}

bool has_all(std::string_view cfg, std::string_view set) {
  return std::all_of(set.begin(), set.end(), [&](char c) { return cfg.find(c) != std::string_view::npos; });
}

bool applies(const BldcRule& rule, std::string_view cfg) {
  return (rule.any.empty() || has_any(cfg, rule.any)) && has_all(cfg, rule.all) && !has_any(cfg, rule.none);
}

void read_bldc(const std::string& source, const YAML::Node& bldc, int& max_instances, std::size_t& cfg_chars,
               std::string& known_letters, std::vector<BldcRule>& rules,
               std::map<std::string, double>& defaults) {
  max_instances = required(source, bldc, "max_instances").as<int>();
  cfg_chars = required(source, bldc, "cfg_chars_read").as<std::size_t>();
  known_letters = letters(source, required(source, bldc, "letters"));
  for (const auto& r : required(source, bldc, "rules")) {
    BldcRule rule{letters(source, r["any"]), letters(source, r["all"]), letters(source, r["none"]),
                  strings(source, r["pins"]), strings(source, r["params"])};
    for (char c : rule.any + rule.all + rule.none)
      if (known_letters.find(c) == std::string::npos)
        reject(source, r, std::string("rule names letter '") + c + "', which is not in `letters`");
    rules.push_back(std::move(rule));
  }
  for (const auto& d : required(source, bldc, "defaults"))
    defaults[d.first.as<std::string>()] = d.second.as<double>();
}

// Every name a bldc rule creates, with its type from `types` (which must know it).
HalObjects bldc_types(const std::string& source, const YAML::Node& bldc, const std::vector<BldcRule>& rules) {
  const auto node = required(source, bldc, "types");
  if (!node.IsMap()) reject(source, node, "expected names with 'TYPE DIRECTION'");
  HalObjects types;
  for (const auto& item : node) types[item.first.as<std::string>()] = hal_object(source, item.second);
  for (const auto& rule : rules)
    for (const auto* names : {&rule.pins, &rule.params})
      for (const auto& name : *names) {
        const auto it = types.find(name);
        if (it == types.end()) reject(source, node, "no type for bldc's '" + name + "'");
        if (it->second.is_param() != (names == &rule.params))
          reject(source, node,
                 "bldc's '" + name + "' is listed as a " + (names == &rule.params ? "param" : "pin") +
                     " but typed otherwise");
      }
  return types;
}

}  // namespace

HalNames HalNames::load_string(std::string_view yaml, const std::string& source) {
  const auto root = params::load_yaml(yaml, source, [](const std::string& where, const std::string& problem) {
    throw UsageError(where + ": " + problem);
  });
  HalNames n;
  std::vector<std::string> i20_outputs, i20_output_params, i20_globals;
  try {
    if (required(source, root, "schema").as<int>() != 1)
      reject(source, root["schema"], "unknown schema (expected 1)");
    read_bldc(source, required(source, root, "bldc"), n.bldc_max_instances_, n.bldc_cfg_chars_,
              n.bldc_letters_, n.bldc_rules_, n.bldc_defaults_);
    n.bldc_types_ = bldc_types(source, required(source, root, "bldc"), n.bldc_rules_);
    const auto i20 = required(source, root, "hm2_8i20");
    n.i20_inputs_ = strings(source, required(source, i20, "inputs"));
    n.i20_input_params_ = strings(source, required(source, i20, "input_params"));
    i20_outputs = strings(source, required(source, i20, "outputs"));
    i20_output_params = strings(source, required(source, i20, "output_params"));
    i20_globals = strings(source, required(source, i20, "globals"));
    n.twin_suffix_ = required(source, i20, "bit_pin_twin_suffix").as<std::string>();
    n.port_pins_ = strings(source, required(source, i20, "port_pins"));
    n.port_params_ = strings(source, required(source, i20, "port_params"));
    for (const auto& o : required(source, root, "obsolete_8i20"))
      n.obsolete_.push_back({required(source, o, "name").as<std::string>(),
                             required(source, o, "kind").as<std::string>(),
                             required(source, o, "replacement").as<std::string>()});
    const auto encoder = required(source, root, "encoder");
    n.encoder_objects_ = hal_objects(source, required(source, encoder, "pins"), false);
    n.encoder_objects_.merge(hal_objects(source, required(source, encoder, "params"), true));
    const auto pid = required(source, root, "pid");
    n.pid_functions_ = strings(source, required(source, pid, "functions"));
    n.pid_objects_ = hal_objects(source, required(source, pid, "pins"), false);
    n.pid_objects_.merge(hal_objects(source, required(source, pid, "params"), true));
    n.pid_debug_objects_ = hal_objects(source, required(source, pid, "debug_params"), true);
  } catch (const YAML::Exception& e) {
    throw UsageError(source + ":" + std::to_string(e.mark.line + 1) + ": " + params::yaml_problem(e));
  }
  // The bit pins are params/faults.yaml's: one list of the 8I20's bits for every tool.
  const auto& table = faults::FaultTable::builtin();
  for (const auto& bit : table.bits(faults::Register::Fault))
    if (!bit.linuxcnc_pin.empty()) n.i20_fault_pins_.push_back(bit.linuxcnc_pin);
  for (const auto& bit : table.bits(faults::Register::Status))
    if (!bit.linuxcnc_pin.empty()) n.i20_status_pins_.push_back(bit.linuxcnc_pin);
  auto bits = n.i20_fault_pins_;
  bits.insert(bits.end(), n.i20_status_pins_.begin(), n.i20_status_pins_.end());
  n.i20_objects_ = i20_table(n.i20_inputs_, n.i20_input_params_, i20_outputs, i20_output_params, i20_globals,
                             bits, n.twin_suffix_);
  return n;
}

std::string HalNames::bldc_letters(std::string_view cfg) const {
  std::string out;
  for (char c : cfg.substr(0, bldc_cfg_chars_))
    if (bldc_letters_.find(c) != std::string::npos && out.find(c) == std::string::npos) out += c;
  return out;
}

BldcNames HalNames::bldc_names(std::string_view cfg) const {
  const std::string read = bldc_letters(cfg);
  BldcNames out;
  for (const auto& rule : bldc_rules_) {
    if (!applies(rule, read)) continue;
    out.pins.insert(rule.pins.begin(), rule.pins.end());
    out.params.insert(rule.params.begin(), rule.params.end());
  }
  return out;
}

const BldcRule* HalNames::bldc_rule_for(const std::string& name) const {
  for (const auto& rule : bldc_rules_) {
    const auto in = [&](const std::vector<std::string>& v) {
      return std::find(v.begin(), v.end(), name) != v.end();
    };
    if (in(rule.pins) || in(rule.params)) return &rule;
  }
  return nullptr;
}

std::optional<double> HalNames::bldc_default(const std::string& name) const {
  const auto it = bldc_defaults_.find(name);
  if (it == bldc_defaults_.end()) return std::nullopt;
  return it->second;
}

HalObjects HalNames::bldc_objects(std::string_view cfg) const {
  const auto made = bldc_names(cfg);
  HalObjects out;
  for (const auto* names : {&made.pins, &made.params})
    for (const auto& name : *names) out[name] = bldc_types_.at(name);
  return out;
}

HalObjects HalNames::pid_objects(bool debug) const {
  auto out = pid_objects_;
  if (debug) out.insert(pid_debug_objects_.begin(), pid_debug_objects_.end());
  return out;
}

const ObsoleteName* HalNames::obsolete_8i20(std::string_view name) const {
  const auto it =
      std::find_if(obsolete_.begin(), obsolete_.end(), [&](const auto& o) { return o.name == name; });
  return it == obsolete_.end() ? nullptr : &*it;
}

}  // namespace i20::linuxcnc
