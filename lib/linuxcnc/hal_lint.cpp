// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_lint.hpp"

#include <algorithm>
#include <cmath>
#include <regex>
#include <set>
#include <sstream>

#include "linuxcnc/hal_design.hpp"

namespace i20::linuxcnc {
namespace {

// hm2_<board>.<n>.8i20.<port>.<channel>.<rest>, or hm2_8i20.<serial>.<rest> when hostmot2
// names remotes by serial number (modparam use_serial_numbers).
struct I20Name {
  std::string device;
  std::string rest;  // leading dots removed (PnCconf writes "..angle")
  bool extra_dots = false;
};

std::optional<I20Name> split_8i20(const std::string& name) {
  static const std::regex kI20(
      R"(^(hm2_[A-Za-z0-9]+\.[0-9]+\.8i20\.[0-9]+\.[0-9]+|hm2_8i20\.[0-9A-Fa-f]+)\.(.*)$)");
  std::smatch m;
  if (!std::regex_match(name, m, kI20)) return std::nullopt;
  std::string rest = m[2].str();
  const auto dots = rest.find_first_not_of('.');
  I20Name out{m[1].str(), dots == std::string::npos ? std::string() : rest.substr(dots), dots != 0};
  return out;
}

// bldc.<N> or bldc.<N>.<rest>.
struct BldcName {
  int index = 0;
  std::string rest;
};

std::optional<BldcName> split_bldc(const std::string& name) {
  // At most 6 digits: a longer number is no instance bldc makes, and would overflow stoi.
  static const std::regex kBldc(R"(^bldc\.([0-9]{1,6})(?:\.(.*))?$)");
  std::smatch m;
  if (!std::regex_match(name, m, kBldc)) return std::nullopt;
  return BldcName{std::stoi(m[1].str()), m[2].str()};
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(item);
  return out;
}

std::string format_number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string letter_list(const std::string& letters, const char* joiner) {
  std::string out;
  for (std::size_t i = 0; i < letters.size(); ++i) {
    if (i) out += i + 1 == letters.size() ? joiner : ", ";
    out += letters[i];
  }
  return out;
}

// "a cfg with a or q", "a cfg with q and without h", for a bldc rule.
std::string rule_condition(const BldcRule& rule) {
  std::string out = "a cfg";
  if (!rule.any.empty()) out += " with " + letter_list(rule.any, " or ");
  if (!rule.all.empty()) out += (rule.any.empty() ? " with " : " and ") + letter_list(rule.all, " and ");
  if (!rule.none.empty())
    out += std::string(rule.any.empty() && rule.all.empty() ? " with" : " and") + " none of " +
           letter_list(rule.none, ", ");
  return out;
}

struct BldcInstance {
  int index = 0;
  std::string cfg;
  SourceLine loaded_at;
};

class Linter {
 public:
  Linter(const std::vector<Statement>& statements, const LintOptions& options, const HalNames& names)
      : design_(statements), options_(options), names_(names) {
    collect_bldc();
    collect_8i20_devices();
  }

  std::vector<LintFinding> run() {
    malformed_names();
    obsolete_8i20_names();
    second_lead();
    current_scaling();
    current_command_limit();
    bldc_names();
    bldc_values();
    bldc_inputs();
    hall_pattern();
    fault_pins();
    pid_inputs();
    return std::move(findings_);
  }

 private:
  void add(const SourceLine& at, LintSeverity severity, std::string rule, std::string message,
           std::string fix) {
    findings_.push_back({at, severity, std::move(rule), std::move(message), std::move(fix)});
  }

  void collect_bldc() {
    bldc_module_ = design_.module("bldc");
    if (bldc_module_ == nullptr) return;
    const auto cfg = bldc_module_->args.find("cfg");
    if (cfg == bldc_module_->args.end()) return;
    // cfg=[BLDC]CFG or $CFG: the instances are known only with the INI file; judge none.
    if (cfg->second.find_first_of("[$") != std::string::npos) {
      bldc_module_ = nullptr;
      return;
    }
    int index = 0;
    for (const auto& one : split_commas(cfg->second)) bldc_.push_back({index++, one, bldc_module_->at});
  }

  void collect_8i20_devices() {
    for (const auto& use : design_.names()) {
      const auto name = split_8i20(use.name);
      if (!name) continue;
      if (std::none_of(devices_.begin(), devices_.end(),
                       [&](const auto& d) { return d.name == name->device; }))
        devices_.push_back({use.at, name->device});
    }
  }

  // The 8I20 pin `rest` of `device` as the files write it (PnCconf's "..angle" included).
  std::vector<std::string> written_8i20_names(const std::string& device, const std::string& rest) const {
    std::vector<std::string> out;
    for (const auto& use : design_.names()) {
      const auto name = split_8i20(use.name);
      if (name && name->device == device && name->rest == rest &&
          std::find(out.begin(), out.end(), use.name) == out.end())
        out.push_back(use.name);
    }
    return out;
  }

  const BldcInstance* bldc(int index) const {
    return index >= 0 && index < static_cast<int>(bldc_.size()) ? &bldc_[static_cast<std::size_t>(index)]
                                                                : nullptr;
  }

  // ---- rules

  void malformed_names() {
    for (const auto& use : design_.names()) {
      const auto& n = use.name;
      if (n.find("..") == std::string::npos && n.front() != '.' && n.back() != '.') continue;
      std::string fixed;
      for (char c : n)
        if (!(c == '.' && (fixed.empty() || fixed.back() == '.'))) fixed += c;
      while (!fixed.empty() && fixed.back() == '.') fixed.pop_back();
      add(use.at, LintSeverity::Error, "malformed-name",
          n + " is not a HAL name: halcmd finds no pin or param with an empty part between dots (PnCconf "
              "writes "
              "the 8I20's prefix with a trailing dot)",
          "write " + fixed);
    }
  }

  void obsolete_8i20_names() {
    for (const auto& use : design_.names()) {
      const auto name = split_8i20(use.name);
      if (!name) continue;
      const auto* old = names_.obsolete_8i20(name->rest);
      if (old == nullptr) continue;
      add(use.at, LintSeverity::Error, "obsolete-8i20-name",
          use.name + ": the 8I20 " + old->kind + " '" + old->name +
              "' was removed from hostmot2 in 2012 (LinuxCNC 2.6): halcmd finds no such " + old->kind,
          old->replacement);
    }
  }

  void second_lead() {
    for (const auto& device : devices_) {
      for (const auto& angle : written_8i20_names(device.name, "angle")) {
        const auto* sig = design_.signal_of(angle);
        if (sig == nullptr) continue;
        const auto angle_use =
            std::find_if(sig->pins.begin(), sig->pins.end(), [&](const auto& p) { return p.name == angle; });
        for (const auto& pin : sig->pins) {
          const auto b = split_bldc(pin.name);
          if (!b || b->rest != "phase-angle") continue;
          const auto lead = lead_of(b->index);
          if (!lead.degrees || *lead.degrees == 0) continue;
          const std::string lead_name = "bldc." + std::to_string(b->index) + ".lead-angle";
          add(angle_use->at, LintSeverity::Error, "second-lead",
              angle + " is fed from " + pin.name + ", which already leads the rotor by " +
                  format_number(*lead.degrees) + " degrees (" + lead.why +
                  "): the 8I20 adds its own lead, so the current leads twice",
              "net bldc." + std::to_string(b->index) + ".rotor-angle to the 8I20's angle instead" +
                  (lead.settable ? ", or setp " + lead_name + " 0" : std::string()));
        }
      }
    }
  }

  struct Lead {
    std::optional<double> degrees;
    std::string why;
    bool settable = true;
  };

  // How far bldc.N's phase-angle leads its rotor-angle.
  Lead lead_of(int index) const {
    const std::string name = "bldc." + std::to_string(index) + ".lead-angle";
    const auto* instance = bldc(index);
    // Without a or q there is no lead-angle pin: the Hall-only (trapezoidal) mode adds a
    // fixed quarter turn.
    if (instance != nullptr && !names_.bldc_names(instance->cfg).has("lead-angle"))
      return {90.0, "fixed in bldc's Hall-only mode, cfg=" + instance->cfg, false};
    if (const auto* set = design_.setting(name))
      return {number(set->value), name + " set at " + set->at.text()};
    if (design_.connected(name)) return {};
    return {names_.bldc_default("lead-angle"), name + " by default"};
  }

  void current_scaling() {
    for (const auto& s : design_.settings()) {
      const auto name = split_8i20(s.name);
      if (!name) continue;
      const auto v = number(s.value);
      if (name->rest == "current-scalemax") {
        add(s.at, LintSeverity::Warning, "current-scaling",
            s.name + " " + s.value +
                ": `current` is in amps because its full scale is the card's MAXCURRENT; another full scale "
                "makes "
                "the pin mean something else (old configs used 1.0 for a +-1 command)",
            "delete this setp and give the current command in amps");
      } else if ((name->rest == "current-maxlim" || name->rest == "current-minlim") && v &&
                 options_.max_current && std::fabs(*v) > *options_.max_current) {
        add(s.at, LintSeverity::Warning, "current-above-max",
            s.name + " " + s.value + " A is beyond MAXCURRENT " + format_number(*options_.max_current) +
                " A: the card clamps there, the limit does nothing",
            "setp " + s.name + " " + (*v < 0 ? "-" : "") + format_number(*options_.max_current) + " or less");
      }
    }
  }

  bool is_pid_output(const std::string& pin) const {
    const auto* pid = design_.module("pid");
    if (pid == nullptr || pin.size() < 7 || pin.compare(pin.size() - 7, 7, ".output") != 0) return false;
    const std::string instance = pin.substr(0, pin.size() - 7);
    const auto names = pid->args.find("names");
    if (names != pid->args.end()) {
      const auto list = split_commas(names->second);
      return std::find(list.begin(), list.end(), instance) != list.end();
    }
    return std::regex_match(instance, std::regex(R"(^pid\.[0-9]+$)"));
  }

  // The pid instances whose output reaches `pin` directly or through a bldc (value -> out).
  // A file may loop a bldc back on itself (its out netted to its own value): each bldc is
  // followed once.
  std::vector<std::string> pids_feeding(const std::string& pin) const {
    std::vector<std::string> out;
    std::set<std::string> followed{pin};
    std::vector<std::string> pending{pin};
    while (!pending.empty()) {
      const auto* sig = design_.signal_of(pending.back());
      pending.pop_back();
      if (sig == nullptr) continue;
      for (const auto& p : sig->pins) {
        if (is_pid_output(p.name)) out.push_back(p.name.substr(0, p.name.size() - 7));
        const auto b = split_bldc(p.name);
        if (!b || b->rest != "out") continue;
        std::string value = "bldc.";
        value += std::to_string(b->index);
        value += ".value";
        if (followed.insert(value).second) pending.push_back(value);
      }
    }
    return out;
  }

  void current_command_limit() {
    if (!options_.max_current) return;
    const double max = *options_.max_current;
    std::set<std::string> seen;
    for (const auto& device : devices_)
      for (const auto& current : written_8i20_names(device.name, "current"))
        for (const auto& pid : pids_feeding(current)) {
          if (!seen.insert(pid).second) continue;
          const std::string name = pid + ".maxoutput";
          const auto* set = design_.setting(name);
          const auto v = set ? number(set->value) : std::optional<double>(0.0);
          if (!v || (*v > 0 && *v <= max)) continue;
          const auto* sig = design_.signal_of(current);
          add(set ? set->at : sig->first, LintSeverity::Warning, "current-above-max",
              current + " is fed from " + pid + " whose maxoutput is " +
                  (*v <= 0 ? "0 (no limit)" : format_number(*v) + " A") +
                  ": the command can exceed MAXCURRENT " + format_number(max) + " A",
              "setp " + name + " " + format_number(max) + " (or less)");
        }
  }

  void bldc_names() {
    if (bldc_module_ == nullptr) return;  // a postgui file alone: the cfg is in another file
    if (bldc_module_->args.count("names") != 0)
      add(bldc_module_->at, LintSeverity::Error, "bldc-instances",
          "bldc takes no names= (LinuxCNC 2.9: \"Unknown parameter\", the module does not load)",
          "delete names=; the instances are bldc.0, bldc.1, ... in cfg order");
    if (bldc_.empty())
      add(bldc_module_->at, LintSeverity::Error, "bldc-instances",
          "loadrt bldc without cfg= makes no instance (bldc needs a feedback letter per motor)",
          "add cfg=, e.g. cfg=qh for Halls, then the encoder");
    if (static_cast<int>(bldc_.size()) > names_.bldc_max_instances())
      add(bldc_module_->at, LintSeverity::Error, "bldc-instances",
          "bldc makes at most " + std::to_string(names_.bldc_max_instances()) + " instances; cfg lists " +
              std::to_string(bldc_.size()),
          "drive at most " + std::to_string(names_.bldc_max_instances()) + " motors from one bldc");
    for (const auto& use : design_.names()) {
      const auto b = split_bldc(use.name);
      if (!b) continue;
      const auto* instance = bldc(b->index);
      if (instance == nullptr) {
        add(use.at, LintSeverity::Error, "bldc-instance",
            use.name + ": bldc." + std::to_string(b->index) + " does not exist, `loadrt bldc` at " +
                bldc_module_->at.text() + " makes " + std::to_string(bldc_.size()) + " instance" +
                (bldc_.size() == 1 ? "" : "s") + " (one per comma-separated cfg string)",
            "add a cfg string for it to the loadrt line, or use an instance that exists");
        continue;
      }
      if (b->rest.empty() || names_.bldc_names(instance->cfg).has(b->rest)) continue;
      const auto* rule = names_.bldc_rule_for(b->rest);
      add(use.at, LintSeverity::Error, "bldc-cfg",
          use.name + " does not exist: bldc." + std::to_string(b->index) +
              " is loaded with cfg=" + instance->cfg +
              (rule ? ", and '" + b->rest + "' exists only with " + rule_condition(*rule)
                    : ", and bldc has no pin or param '" + b->rest + "'"),
          rule ? "delete this line, or change the cfg at " + instance->loaded_at.text() : "delete this line");
    }
  }

  void bldc_values() {
    for (const auto& s : design_.settings()) {
      const auto b = split_bldc(s.name);
      const auto v = number(s.value);
      if (!b || !v) continue;
      if (b->rest == "initvalue" && *v == 0)
        add(s.at, LintSeverity::Warning, "initvalue-zero",
            s.name +
                " 0: the q-mode alignment runs with no drive, so the offset it measures is wrong (PnCconf "
                "prints "
                "the default 0.2 as 0)",
            "setp " + s.name + " 0.2, or the fraction of full output the alignment needs");
      if (b->rest == "drive-offset" && (*v < 0 || *v > 360))
        add(s.at, LintSeverity::Warning, "angle-range",
            s.name + " " + s.value + ": drive-offset is an angle in degrees, 0 to 360",
            "give it in 0..360 degrees");
      if (b->rest == "lead-angle" && std::fabs(*v) > 360)
        add(s.at, LintSeverity::Warning, "angle-range",
            s.name + " " + s.value + ": lead-angle is in degrees; more than a full turn is not a lead",
            "give it in degrees, -360..360 (0 when feeding an 8I20 from rotor-angle)");
      if ((b->rest == "lead-angle" || b->rest == "drive-offset") && *v != 0 && std::fabs(*v) < 1)
        add(s.at, LintSeverity::Warning, "angle-range",
            s.name + " " + s.value + ": this is in degrees, not in turns; " + s.value +
                " is less than one degree",
            "give it in degrees (a quarter turn is 90)");
    }
  }

  void bldc_inputs() {
    for (const auto& instance : bldc_) {
      const auto made = names_.bldc_names(instance.cfg);
      const std::string prefix = "bldc." + std::to_string(instance.index) + ".";
      for (const char* input : {"rawcounts", "hall1", "hall2", "hall3"}) {
        if (made.pins.count(input) == 0 || design_.connected(prefix + input)) continue;
        add(instance.loaded_at, LintSeverity::Error, "bldc-input",
            prefix + input + " is connected to nothing: bldc." + std::to_string(instance.index) +
                " (cfg=" + instance.cfg + ") commutates from it",
            std::string("net it to the ") +
                (std::string(input) == "rawcounts" ? "encoder's rawcounts" : "Hall sensor's input pin"));
      }
    }
  }

  void hall_pattern() {
    if (!options_.pattern) return;
    for (const auto& instance : bldc_) {
      if (names_.bldc_names(instance.cfg).params.count("pattern") == 0) continue;
      const std::string name = "bldc." + std::to_string(instance.index) + ".pattern";
      const auto* set = design_.setting(name);
      const auto v = set ? number(set->value) : names_.bldc_default("pattern");
      if (!v || *v == *options_.pattern) continue;
      add(set ? set->at : instance.loaded_at, LintSeverity::Error, "hall-pattern",
          name + " is " + format_number(*v) + (set ? "" : " (its default)") +
              ", but commissioning found the motor's Halls follow pattern " +
              std::to_string(*options_.pattern),
          "setp " + name + " " + std::to_string(*options_.pattern));
    }
  }

  void fault_pins() {
    for (const auto& device : devices_) {
      bool reaches = false;
      for (const auto& use : design_.names()) {
        const auto name = split_8i20(use.name);
        if (name && name->device == device.name && name->rest.rfind("fault.", 0) == 0 &&
            design_.connected(use.name))
          reaches = true;
      }
      if (reaches) continue;
      add(device.first, LintSeverity::Warning, "faults-unconnected",
          "no fault pin of " + device.name +
              " is connected: an 8I20 fault turns its output off but does not stop "
              "the machine, which keeps commanding motion",
          "or its fault.* pins (fault.watchdog, fault.overcurrent, ...) into the E-stop chain "
          "(iocontrol.0.emc-enable-in), e.g. with the logic component; `i20 hal` writes such a chain");
    }
  }

  // True when something besides `pin` and the 8I20's own inputs (angle, current, the
  // obsolete amp_enable) is on its signal: PnCconf nets x-enable to pid.N.enable and
  // amp_enable only, which leaves both undriven.
  bool driven(const std::string& pin) const {
    const auto* sig = design_.signal_of(pin);
    if (sig == nullptr) return false;
    if (sig->set_by_sets) return true;
    return std::any_of(sig->pins.begin(), sig->pins.end(), [&](const auto& p) {
      if (p.name == pin) return false;
      const auto i20 = split_8i20(p.name);
      return !(i20 && (i20->rest == "angle" || i20->rest == "current" ||
                       names_.obsolete_8i20(i20->rest) != nullptr));
    });
  }

  void pid_inputs() {
    std::set<std::string> seen;
    for (const auto& device : devices_)
      for (const auto& current : written_8i20_names(device.name, "current"))
        for (const auto& pid : pids_feeding(current)) {
          if (!seen.insert(pid).second) continue;
          for (const char* input : {"command", "feedback", "enable"}) {
            const std::string pin = pid + "." + input;
            if (driven(pin)) continue;
            const auto* sig = design_.signal_of(pin);
            add(sig ? sig->first : design_.signal_of(current)->first, LintSeverity::Error, "pid-input",
                pin +
                    (sig ? " is on signal " + sig->name + ", which nothing drives"
                         : " is connected to nothing") +
                    ": " + pid + " drives " + current + " from it",
                std::string("net it to ") + (std::string(input) == "command" ? "the joint's motor-pos-cmd"
                                             : std::string(input) == "feedback"
                                                 ? "the encoder's position"
                                                 : "the joint's amp-enable-out"));
          }
        }
  }

  struct Device {
    SourceLine first;
    std::string name;
  };

  HalDesign design_;
  const LintOptions& options_;
  const HalNames& names_;
  const LoadedModule* bldc_module_ = nullptr;
  std::vector<BldcInstance> bldc_;
  std::vector<Device> devices_;
  std::vector<LintFinding> findings_;
};

}  // namespace

std::vector<LintFinding> lint(const std::vector<Statement>& statements, const LintOptions& options,
                              const HalNames& names) {
  auto findings = Linter(statements, options, names).run();
  std::vector<std::string> file_order;
  for (const auto& s : statements)
    if (std::find(file_order.begin(), file_order.end(), s.at.file) == file_order.end())
      file_order.push_back(s.at.file);
  const auto rank = [&](const SourceLine& at) {
    return std::make_pair(std::find(file_order.begin(), file_order.end(), at.file) - file_order.begin(),
                          at.line);
  };
  std::stable_sort(findings.begin(), findings.end(),
                   [&](const auto& a, const auto& b) { return rank(a.at) < rank(b.at); });
  return findings;
}

std::string to_string(const LintFinding& finding) {
  std::string out = finding.at.text() + ": " +
                    (finding.severity == LintSeverity::Error ? "error" : "warning") + ": " + finding.message;
  if (!finding.fix.empty()) out += " (fix: " + finding.fix + ")";
  return out;
}

}  // namespace i20::linuxcnc
