// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_design.hpp"

#include <algorithm>
#include <cstdlib>

namespace i20::linuxcnc {

HalDesign::HalDesign(const std::vector<Statement>& statements) {
  for (const auto& s : statements) statement(s);
}

void HalDesign::statement(const Statement& s) {
  const auto& a = s.args;
  if (s.command == "loadrt" || s.command == "loadusr") {
    LoadedModule m{s.at, a.front(), {}, s.command == "loadrt"};
    for (std::size_t i = 1; i < a.size(); ++i) {
      const std::string word = unquoted(a[i]);
      const auto eq = word.find('=');
      if (eq != std::string::npos) m.args[word.substr(0, eq)] = word.substr(eq + 1);
    }
    modules_.push_back(std::move(m));
  } else if (s.command == "setp") {
    names_.push_back(use(s.at, a[0], true));
    const auto& name = names_.back();
    const auto linked = signal_of_pin_.find(name.name);
    settings_.push_back(
        {s.at, name.name, a[1], name.written, linked == signal_of_pin_.end() ? "" : linked->second});
  } else if (s.command == "net") {
    for (std::size_t i = 1; i < a.size(); ++i) {
      names_.push_back(use(s.at, a[i], false));
      link(a[0], names_.back());
    }
  } else if (s.command == "linkps" || s.command == "linksp") {
    const bool pin_first = s.command == "linkps";
    names_.push_back(use(s.at, pin_first ? a[0] : a[1], false));
    link(pin_first ? a[1] : a[0], names_.back());
  } else if (s.command == "linkpp") {
    // halcmd makes a signal named after the first pin.
    for (const auto& pin : a) {
      names_.push_back(use(s.at, pin, false));
      link(a[0], names_.back());
    }
  } else if (s.command == "sets") {
    auto& sig = signals_[a[0]];
    const bool existed = !sig.name.empty();
    if (!existed) sig = Signal{a[0], s.at, {}, false, {}};
    signal_values_.push_back({s.at, a[0], sig.pins.size(), existed});
    sig.set_by_sets = true;
  } else if (s.command == "newsig") {
    auto& sig = signals_[a[0]];
    if (sig.name.empty() || (sig.pins.empty() && sig.declared_type.empty())) sig.first = s.at;
    sig.name = a[0];
    sig.declared_type = a[1];
  } else if (s.command == "addf") {
    names_.push_back({s.at, a[0], {}});
    functions_.push_back(names_.back());
  } else if (s.command == "getp" || s.command == "ptype") {
    names_.push_back(use(s.at, a[0], true));
  } else if (s.command == "alias") {
    alias(s);
  } else if (s.command == "unalias") {
    unalias(s);
  }
}

NameUse HalDesign::use(const SourceLine& at, const std::string& written, bool or_param) const {
  if (const auto pin = pin_aliases_.find(written); pin != pin_aliases_.end())
    return {at, pin->second, written};
  if (or_param)
    if (const auto param = param_aliases_.find(written); param != param_aliases_.end())
      return {at, param->second, written};
  return {at, written, {}};
}

// alias pin|param NAME ALIAS: from here on ALIAS names NAME's pin or param. NAME may itself be
// an alias (HAL finds the object by either name); NAME stays usable.
void HalDesign::alias(const Statement& s) {
  const bool pin = s.args[0] == "pin";
  auto& aliases = pin ? pin_aliases_ : param_aliases_;
  const auto it = aliases.find(s.args[1]);
  const std::string real = it == aliases.end() ? s.args[1] : it->second;
  names_.push_back({s.at, real, it == aliases.end() ? "" : s.args[1]});
  // An object has one alias: a new one replaces the old.
  std::erase_if(aliases, [&](const auto& entry) { return entry.second == real; });
  aliases[s.args[2]] = real;
}

// unalias pin|param NAME: the object (named by its alias or its own name) has no alias.
void HalDesign::unalias(const Statement& s) {
  auto& aliases = s.args[0] == "pin" ? pin_aliases_ : param_aliases_;
  const auto it = aliases.find(s.args[1]);
  const std::string real = it == aliases.end() ? s.args[1] : it->second;
  std::erase_if(aliases, [&](const auto& entry) { return entry.second == real; });
}

void HalDesign::link(const std::string& signal, const NameUse& pin) {
  auto& sig = signals_[signal];
  if (sig.name.empty()) sig = Signal{signal, pin.at, {}, false, {}};
  // A signal a `sets` named before anything made it is made here.
  if (sig.pins.empty() && sig.declared_type.empty()) sig.first = pin.at;
  const auto on = signal_of_pin_.find(pin.name);
  if (on != signal_of_pin_.end()) {
    // Linking a pin to its own signal again is a no-op; to another one halcmd refuses.
    if (on->second != signal) relinks_.push_back({pin, on->second, signal});
    return;
  }
  sig.pins.push_back(pin);
  signal_of_pin_.emplace(pin.name, signal);
}

const LoadedModule* HalDesign::module(std::string_view name) const {
  const auto it =
      std::find_if(modules_.begin(), modules_.end(), [&](const auto& m) { return m.name == name; });
  return it == modules_.end() ? nullptr : &*it;
}

const Setting* HalDesign::setting(std::string_view name) const {
  const auto it =
      std::find_if(settings_.rbegin(), settings_.rend(), [&](const auto& s) { return s.name == name; });
  return it == settings_.rend() ? nullptr : &*it;
}

const Signal* HalDesign::signal_of(std::string_view pin) const {
  const auto it = signal_of_pin_.find(std::string(pin));
  return it == signal_of_pin_.end() ? nullptr : &signals_.at(it->second);
}

bool HalDesign::connected(std::string_view pin) const {
  const auto* sig = signal_of(pin);
  if (sig == nullptr) return false;
  if (sig->set_by_sets) return true;
  return std::any_of(sig->pins.begin(), sig->pins.end(), [&](const auto& p) { return p.name != pin; });
}

std::optional<double> number(std::string_view value) {
  const std::string text(value);
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size()) return std::nullopt;
  return v;
}

}  // namespace i20::linuxcnc
