// SPDX-License-Identifier: GPL-2.0-or-later
// What LinuxCNC calls the parts of an 8I20 axis, as data (params/linuxcnc-hal.yaml, and
// the fault/status bit pins of params/faults.yaml): which pins and params a bldc cfg
// string creates, every hostmot2 8I20, encoder and pid pin and param with its HAL type and
// direction, and the 8I20 names hostmot2 dropped in 2012 with what replaced them.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace i20::linuxcnc {

// The pins and params one bldc instance has (names after "bldc.N.").
struct BldcNames {
  std::set<std::string> pins;
  std::set<std::string> params;
  bool has(const std::string& name) const { return pins.count(name) != 0 || params.count(name) != 0; }
};

// One bldc creation rule: its names exist when the cfg has a letter of `any` (empty: no
// condition), every letter of `all` and no letter of `none`.
struct BldcRule {
  std::string any, all, none;
  std::vector<std::string> pins, params;
};

// What HAL says a pin or param is, as halcmd's `show` lists it: its type and its direction
// (pins: in, out, io; params: rw, ro).
struct HalObject {
  std::string type;       // bit | float | s32 | u32
  std::string direction;  // in | out | io | rw | ro
  bool is_param() const { return direction == "rw" || direction == "ro"; }
  // halcmd's setp refuses an output pin and a read-only param ("is not writable").
  bool settable() const { return direction != "out" && direction != "ro"; }
};

// The names after an instance's prefix ("angle", "fault.watchdog", "do-pid-calcs.time")
// and what each is.
using HalObjects = std::map<std::string, HalObject>;

struct ObsoleteName {
  std::string name;         // after hm2_<board>.<n>.8i20.<port>.<channel>.
  std::string kind;         // pin | param
  std::string replacement;  // the fix, an instruction: "use the bus-voltage pin (volts)"
};

class HalNames {
 public:
  // params/linuxcnc-hal.yaml compiled in, with the bit pins of params/faults.yaml.
  static const HalNames& builtin();
  // Throws UsageError naming `source` when the YAML is not of the documented shape.
  static HalNames load_string(std::string_view yaml, const std::string& source);

  // ---- bldc
  int bldc_max_instances() const { return bldc_max_instances_; }
  // The names of an instance loaded with `cfg` (only its first 8 characters count).
  BldcNames bldc_names(std::string_view cfg) const;
  // The letters of cfg that bldc reads (others are ignored), in order, without repeats.
  std::string bldc_letters(std::string_view cfg) const;
  // The rule that would create `name`, for a message ("needs a or q"); nullptr if none.
  const BldcRule* bldc_rule_for(const std::string& name) const;
  // A pin's or param's starting value (lead-angle 90, initvalue 0.2, ...), if known.
  std::optional<double> bldc_default(const std::string& name) const;
  // The pins and params of an instance loaded with `cfg`, with their types.
  HalObjects bldc_objects(std::string_view cfg) const;
  // Every pin and param some cfg creates: what a bldc name can be when the cfg is unknown.
  const HalObjects& bldc_any_cfg_objects() const { return bldc_types_; }

  // ---- hostmot2 8I20 (names after hm2_<board>.<n>.8i20.<port>.<channel>.)
  const std::vector<std::string>& i20_inputs() const { return i20_inputs_; }
  const std::vector<std::string>& i20_input_params() const { return i20_input_params_; }
  const std::vector<std::string>& i20_fault_pins() const { return i20_fault_pins_; }
  const std::vector<std::string>& i20_status_pins() const { return i20_status_pins_; }
  const std::string& bit_pin_twin_suffix() const { return twin_suffix_; }
  const ObsoleteName* obsolete_8i20(std::string_view name) const;
  const std::vector<ObsoleteName>& obsolete_8i20_names() const { return obsolete_; }
  const std::vector<std::string>& port_pins() const { return port_pins_; }
  // Every pin and param hostmot2 makes for one 8I20 (its fixed table), with its type.
  const HalObjects& i20_objects() const { return i20_objects_; }

  // ---- hostmot2 encoder (names after hm2_<board>.<n>.encoder.<NN>.)
  const HalObjects& encoder_objects() const { return encoder_objects_; }

  // ---- pid (names after pid.<N>. or after a names= name)
  // `debug`: loaded with debug=1, which adds a few read-only params.
  HalObjects pid_objects(bool debug) const;
  // The functions of one instance, after its prefix: do-pid-calcs.
  const std::vector<std::string>& pid_functions() const { return pid_functions_; }

 private:
  int bldc_max_instances_ = 0;
  std::size_t bldc_cfg_chars_ = 0;
  std::string bldc_letters_;
  std::vector<BldcRule> bldc_rules_;
  std::map<std::string, double> bldc_defaults_;
  HalObjects bldc_types_;
  std::vector<std::string> i20_inputs_, i20_input_params_;
  std::vector<std::string> i20_fault_pins_, i20_status_pins_;
  std::string twin_suffix_;
  std::vector<std::string> port_pins_, port_params_;
  std::vector<ObsoleteName> obsolete_;
  HalObjects i20_objects_;
  HalObjects encoder_objects_;
  HalObjects pid_objects_, pid_debug_objects_;
  std::vector<std::string> pid_functions_;
};

}  // namespace i20::linuxcnc
