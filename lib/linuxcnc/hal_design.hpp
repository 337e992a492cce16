// SPDX-License-Identifier: GPL-2.0-or-later
// What a set of HAL statements builds, without running it: the modules loaded, the values
// set, which pins share which signal, and every name mentioned with where. The linter's
// view of a configuration (all its HAL files together, in the order LinuxCNC runs them).
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
};

// A setp (or `name = value`): the last one of a name wins, as it does in HAL.
struct Setting {
  SourceLine at;
  std::string name;
  std::string value;
};

// A pin, param or function name as written, and where.
struct NameUse {
  SourceLine at;
  std::string name;
};

struct Signal {
  std::string name;
  SourceLine first;           // the first net/link that made it
  std::vector<NameUse> pins;  // every pin linked to it
  bool set_by_sets = false;   // a `sets` gives it a value
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

 private:
  void link(const std::string& signal, const NameUse& pin);

  std::vector<LoadedModule> modules_;
  std::vector<Setting> settings_;
  std::map<std::string, Signal> signals_;
  std::map<std::string, std::string> signal_of_pin_;
  std::vector<NameUse> names_;
};

// A number as halcmd would read it for a float; nullopt for INI or environment references
// ([JOINT_0]SCALE, $VAR) and anything else that is not a plain number.
std::optional<double> number(std::string_view value);

}  // namespace i20::linuxcnc
