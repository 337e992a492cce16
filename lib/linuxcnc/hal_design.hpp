// SPDX-License-Identifier: GPL-2.0-or-later
// What a set of HAL statements builds, without running it: the modules loaded, the values
// set, which pins share which signal, and every name mentioned with where. The linter's
// view of a configuration (all its HAL files together, in the order LinuxCNC runs them).
// Names reached through halcmd's `alias pin|param NAME ALIAS` are recorded as the real
// NAME (HAL finds a pin or param by its alias and by its own name alike), so every rule
// judges the real name. The statements halcmd refuses by its own rules are kept in order
// (a second signal for a linked pin, sets, newsig) for the linter to judge.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "linuxcnc/hal_file.hpp"

namespace i20::linuxcnc {

// A `loadrt` or `loadusr`: the module and its name=value arguments (quotes removed).
struct LoadedModule {
  SourceLine at;
  std::string name;
  std::map<std::string, std::string> args;
  bool realtime = true;  // loadrt (false: loadusr)
};

// A pin, param or function name, and where. `name` is the real name; `written` is the
// alias the file wrote instead, if it did ("" otherwise).
struct NameUse {
  SourceLine at;
  std::string name;
  std::string written;
  // "NAME" or "NAME (written as ALIAS)", for messages.
  std::string shown() const { return written.empty() ? name : name + " (written as " + written + ")"; }
};

// A setp (or `name = value`): the last one of a name wins, as it does in HAL.
struct Setting {
  SourceLine at;
  std::string name;  // the real name
  std::string value;
  std::string written;    // the alias written, if any
  std::string linked_to;  // the signal the pin was on when this setp ran ("" none)
};

struct Signal {
  std::string name;
  SourceLine first;           // the first net/link/newsig that made it
  std::vector<NameUse> pins;  // every pin linked to it, in order, each once
  bool set_by_sets = false;   // a `sets` gives it a value
  std::string declared_type;  // newsig's type ("" none)
};

// A net or link of a pin already on another signal: halcmd refuses it, the pin stays where
// it was.
struct Relink {
  NameUse pin;
  std::string linked_to;  // the signal it is on
  std::string refused;    // the signal the statement named
};

// A `sets`: `pins_before` pins were on the signal then; `signal_existed` says whether a net
// or newsig had made it (halcmd's sets does not make a signal).
struct SignalValue {
  SourceLine at;
  std::string signal;
  std::size_t pins_before = 0;
  bool signal_existed = false;
};

class HalDesign {
 public:
  explicit HalDesign(const std::vector<Statement>& statements);

  const std::vector<LoadedModule>& modules() const { return modules_; }
  // The first loadrt/loadusr of `name` (LinuxCNC loads a module once), nullptr if none.
  const LoadedModule* module(std::string_view name) const;
  // The value a setp gave `name` last, nullptr if none.
  const Setting* setting(std::string_view name) const;
  const std::vector<Setting>& settings() const { return settings_; }
  const std::map<std::string, Signal>& signals() const { return signals_; }
  // The signal `pin` is linked to, nullptr if none.
  const Signal* signal_of(std::string_view pin) const;
  // True when `pin` is on a signal that also has another pin or a sets value.
  bool connected(std::string_view pin) const;
  // Every pin, param and function name the statements mention, in order.
  const std::vector<NameUse>& names() const { return names_; }
  // The function names of the addf statements, in order.
  const std::vector<NameUse>& functions() const { return functions_; }
  const std::vector<Relink>& relinks() const { return relinks_; }
  const std::vector<SignalValue>& signal_values() const { return signal_values_; }

 private:
  void statement(const Statement& s);
  void link(const std::string& signal, const NameUse& pin);
  void alias(const Statement& s);
  void unalias(const Statement& s);
  // The real name of `written` (a pin's alias; with `or_param` also a param's), as a use.
  NameUse use(const SourceLine& at, const std::string& written, bool or_param) const;

  std::vector<LoadedModule> modules_;
  std::vector<Setting> settings_;
  std::map<std::string, Signal> signals_;
  std::map<std::string, std::string> signal_of_pin_;
  std::vector<NameUse> names_;
  std::vector<NameUse> functions_;
  std::vector<Relink> relinks_;
  std::vector<SignalValue> signal_values_;
  std::map<std::string, std::string> pin_aliases_, param_aliases_;  // alias -> real name
};

// A number as halcmd would read it for a float; nullopt for INI or environment references
// ([JOINT_0]SCALE, $VAR) and anything else that is not a plain number.
std::optional<double> number(std::string_view value);

}  // namespace i20::linuxcnc
