// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_design.hpp"

#include <algorithm>
#include <cstdlib>

namespace i20::linuxcnc {

HalDesign::HalDesign(const std::vector<Statement>& statements) {
  for (const auto& s : statements) {
    const auto& a = s.args;
    if (s.command == "loadrt" || s.command == "loadusr") {
      LoadedModule m{s.at, a.front(), {}};
      for (std::size_t i = 1; i < a.size(); ++i) {
        const std::string word = unquoted(a[i]);
        const auto eq = word.find('=');
        if (eq != std::string::npos) m.args[word.substr(0, eq)] = word.substr(eq + 1);
      }
      modules_.push_back(std::move(m));
    } else if (s.command == "setp") {
      settings_.push_back({s.at, a[0], a[1]});
      names_.push_back({s.at, a[0]});
    } else if (s.command == "net") {
      for (std::size_t i = 1; i < a.size(); ++i) {
        names_.push_back({s.at, a[i]});
        link(a[0], names_.back());
      }
      if (a.size() == 1) link(a[0], {s.at, {}});
    } else if (s.command == "linkps" || s.command == "linksp") {
      const bool pin_first = s.command == "linkps";
      names_.push_back({s.at, pin_first ? a[0] : a[1]});
      link(pin_first ? a[1] : a[0], names_.back());
    } else if (s.command == "linkpp") {
      // halcmd makes a signal named after the first pin.
      for (const auto& pin : a) {
        names_.push_back({s.at, pin});
        link(a[0], names_.back());
      }
    } else if (s.command == "sets") {
      auto& sig = signals_[a[0]];
      if (sig.name.empty()) sig = Signal{a[0], s.at, {}, false};
      sig.set_by_sets = true;
    } else if (s.command == "addf") {
      names_.push_back({s.at, a[0]});
    }
  }
}

void HalDesign::link(const std::string& signal, const NameUse& pin) {
  auto& sig = signals_[signal];
  if (sig.name.empty()) sig = Signal{signal, pin.at, {}, false};
  if (pin.name.empty()) return;
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
