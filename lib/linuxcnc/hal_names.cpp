// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_names.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>

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

}  // namespace

HalNames HalNames::load_string(std::string_view yaml, const std::string& source) {
  const auto root = params::load_yaml(yaml, source, [](const std::string& where, const std::string& problem) {
    throw UsageError(where + ": " + problem);
  });
  HalNames n;
  try {
    if (required(source, root, "schema").as<int>() != 1)
      reject(source, root["schema"], "unknown schema (expected 1)");
    read_bldc(source, required(source, root, "bldc"), n.bldc_max_instances_, n.bldc_cfg_chars_,
              n.bldc_letters_, n.bldc_rules_, n.bldc_defaults_);
    const auto i20 = required(source, root, "hm2_8i20");
    n.i20_inputs_ = strings(source, required(source, i20, "inputs"));
    n.i20_input_params_ = strings(source, required(source, i20, "input_params"));
    n.i20_outputs_ = strings(source, required(source, i20, "outputs"));
    n.i20_globals_ = strings(source, required(source, i20, "globals"));
    n.twin_suffix_ = required(source, i20, "bit_pin_twin_suffix").as<std::string>();
    n.port_pins_ = strings(source, required(source, i20, "port_pins"));
    n.port_params_ = strings(source, required(source, i20, "port_params"));
    for (const auto& o : required(source, root, "obsolete_8i20"))
      n.obsolete_.push_back({required(source, o, "name").as<std::string>(),
                             required(source, o, "kind").as<std::string>(),
                             required(source, o, "replacement").as<std::string>()});
    const auto encoder = required(source, root, "encoder");
    n.encoder_pins_ = strings(source, required(source, encoder, "pins"));
    n.encoder_params_ = strings(source, required(source, encoder, "params"));
  } catch (const YAML::Exception& e) {
    throw UsageError(source + ":" + std::to_string(e.mark.line + 1) + ": " + params::yaml_problem(e));
  }
  // The bit pins are params/faults.yaml's: one list of the 8I20's bits for every tool.
  const auto& table = faults::FaultTable::builtin();
  for (const auto& bit : table.bits(faults::Register::Fault))
    if (!bit.linuxcnc_pin.empty()) n.i20_fault_pins_.push_back(bit.linuxcnc_pin);
  for (const auto& bit : table.bits(faults::Register::Status))
    if (!bit.linuxcnc_pin.empty()) n.i20_status_pins_.push_back(bit.linuxcnc_pin);
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

const ObsoleteName* HalNames::obsolete_8i20(std::string_view name) const {
  const auto it =
      std::find_if(obsolete_.begin(), obsolete_.end(), [&](const auto& o) { return o.name == name; });
  return it == obsolete_.end() ? nullptr : &*it;
}

}  // namespace i20::linuxcnc
