// SPDX-License-Identifier: GPL-2.0-or-later
#include "linuxcnc/hal_lint.hpp"

#include <algorithm>
#include <cmath>
#include <map>
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

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of two
// neighbours ("angel" -> "angle" is 1).
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i)
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// The names closest to a misspelt `word` (at most two edits, and fewer for short words),
// all of them when several are equally close.
std::vector<std::string> nearest(const std::string& word, const HalObjects& objects,
                                 const std::vector<std::string>& functions = {}) {
  const std::size_t limit = std::clamp<std::size_t>(word.size() / 3, 1, 2);
  std::size_t best = limit + 1;
  std::vector<std::string> out;
  const auto consider = [&](const std::string& name) {
    const auto d = edit_distance(word, name);
    if (d > best) return;
    if (d < best) out.clear();
    best = d;
    out.push_back(name);
  };
  for (const auto& [name, object] : objects) consider(name);
  for (const auto& name : functions) consider(name);
  return out;
}

std::string either_of(const std::vector<std::string>& names, const std::string& prefix) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) out += i + 1 == names.size() ? " or " : ", ";
    out += prefix + names[i];
  }
  return out;
}

// What `pin`'s direction means for a signal: halcmd allows one writer (an out pin), or any
// number of io pins and no out pin.
std::string describe(const HalObject& o) {
  return o.type + " " + (o.direction == "io" ? "I/O" : o.direction);
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
    module_loaded_twice();
    pin_on_two_signals();
    signal_pins();
    setp_refused();
    sets_refused();
    signal_type_names();
    function_added_twice();
    unknown_names();
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
    findings_.push_back({at, severity, std::move(rule), std::move(message), std::move(fix), false});
  }

  // A statement halcmd refuses by its own rules: an error, and the file does not load.
  void refused(const SourceLine& at, std::string rule, std::string message, std::string fix) {
    findings_.push_back({at, LintSeverity::Error, std::move(rule),
                         std::move(message) + " (halcmd refuses this line)", std::move(fix), true});
  }

  // ---- the instances of the components whose names are known: 8I20, encoder, bldc, pid

  struct Instance {
    std::string kind;  // what makes it, for messages: "hostmot2's 8I20", "bldc.0 (cfg=qh)", ...
    std::string rest;  // the name after the instance's prefix
    HalObjects objects;
    std::vector<std::string> functions;  // rests that are the instance's functions
    bool judged_elsewhere = false;       // obsolete, malformed or bldc: their own rules speak
  };

  // The known instance `name` belongs to, if any.
  std::optional<Instance> instance_of(const std::string& name) const {
    if (const auto i20 = split_8i20(name)) {
      const bool elsewhere = i20->extra_dots || names_.obsolete_8i20(i20->rest) != nullptr;
      return Instance{"hostmot2's 8I20", i20->rest, names_.i20_objects(), {}, elsewhere};
    }
    static const std::regex kEncoder(R"(^hm2_[A-Za-z0-9]+\.[0-9]+\.encoder\.[0-9]{2}\.(.+)$)");
    std::smatch m;
    if (std::regex_match(name, m, kEncoder))
      return Instance{"hostmot2's encoder", m[1].str(), names_.encoder_objects(), {}, false};
    if (const auto b = split_bldc(name)) {
      if (b->rest.empty()) return std::nullopt;  // bldc.N is the function
      if (bldc_module_ == nullptr) return Instance{"bldc", b->rest, names_.bldc_any_cfg_objects(), {}, false};
      const auto* instance = bldc(b->index);
      if (instance == nullptr) return std::nullopt;  // bldc-instance says so
      return Instance{"bldc." + std::to_string(b->index) + " (cfg=" + instance->cfg + ")",
                      b->rest,
                      names_.bldc_objects(instance->cfg),
                      {},
                      true};
    }
    for (const auto& prefix : pid_prefixes())
      if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0)
        return Instance{"pid", name.substr(prefix.size()), names_.pid_objects(pid_debug()),
                        names_.pid_functions(), false};
    static const std::regex kPid(R"(^pid\.[0-9]+\.(.+)$)");
    if (std::regex_match(name, m, kPid))
      return Instance{"pid", m[1].str(), names_.pid_objects(pid_debug()), names_.pid_functions(), false};
    return std::nullopt;
  }

  // "pid.x." for each names= of `loadrt pid`.
  std::vector<std::string> pid_prefixes() const {
    std::vector<std::string> out;
    const auto* pid = design_.module("pid");
    if (pid == nullptr) return out;
    const auto names = pid->args.find("names");
    if (names == pid->args.end()) return out;
    for (const auto& n : split_commas(names->second)) out.push_back(n + ".");
    return out;
  }

  // pid's debug=1 params exist; without the loadrt line in the files, they may.
  bool pid_debug() const {
    const auto* pid = design_.module("pid");
    if (pid == nullptr) return true;
    const auto debug = pid->args.find("debug");
    return debug != pid->args.end() && number(debug->second).value_or(0) != 0;
  }

  // What `name` is when a known component makes it; nullopt otherwise (another component's,
  // or a name that does not exist).
  std::optional<HalObject> object_of(const std::string& name) const {
    const auto instance = instance_of(name);
    if (!instance) return std::nullopt;
    const auto it = instance->objects.find(instance->rest);
    if (it == instance->objects.end()) return std::nullopt;
    return it->second;
  }

  // ---- what halcmd refuses by its own rules

  void module_loaded_twice() {
    std::map<std::string, const LoadedModule*> first;
    for (const auto& m : design_.modules()) {
      if (!m.realtime) continue;
      const auto [it, fresh] = first.emplace(unquoted(m.name), &m);
      if (fresh) continue;
      refused(m.at, "module-loaded-twice",
              "loadrt " + m.name + ": the module is already loaded at " + it->second->at.text() +
                  ", and a module loads once (halcmd: \"" + m.name + ": already exists\")",
              "load it once, with every instance on that line (bldc cfg=qh,qh; pid names=pid.x,pid.y); when "
              "adding a fragment (i20 commission's), delete its loadrt and add its instance there");
    }
  }

  void pin_on_two_signals() {
    for (const auto& r : design_.relinks()) {
      const auto* on = design_.signals().count(r.linked_to) ? &design_.signals().at(r.linked_to) : nullptr;
      std::string where;
      if (on != nullptr)
        for (const auto& p : on->pins)
          if (p.name == r.pin.name) where = " at " + p.at.text();
      refused(r.pin.at, "pin-on-two-signals",
              r.pin.shown() + " is already on signal " + r.linked_to + where +
                  "; a pin is on one signal, so " + r.refused + " cannot take it",
              "net it once: put what needs its value on signal " + r.linked_to + ", or rename " + r.refused +
                  " to " + r.linked_to);
    }
  }

  // One signal: every pin of one type (the newsig type or the first known pin's), and one
  // writer (an out pin) or else only io pins. Pins of other components are not judged.
  void signal_pins() {
    for (const auto& [name, sig] : design_.signals()) {
      std::optional<std::pair<std::string, std::string>> type;  // type, and who set it
      if (!sig.declared_type.empty()) type = {sig.declared_type, "newsig at " + sig.first.text()};
      const NameUse* writer = nullptr;
      const NameUse* io = nullptr;
      for (const auto& pin : sig.pins) {
        const auto o = object_of(pin.name);
        if (!o) continue;
        if (!type) {
          type = {o->type, pin.name + " at " + pin.at.text()};
        } else if (type->first != o->type) {
          refused(pin.at, "signal-type",
                  "signal " + name + " is " + type->first + " (" + type->second + "), and " + pin.shown() +
                      " is " + o->type + ": a signal links pins of one type",
                  "use another signal for " + pin.name + ", or a conversion component (conv_*) between them");
          continue;
        }
        const NameUse* clash = o->direction == "out"  ? (writer ? writer : io)
                               : o->direction == "io" ? writer
                                                      : nullptr;
        if (clash != nullptr)
          refused(pin.at, "signal-writers",
                  "signal " + name + " already has " + (clash == writer ? "the output " : "the I/O pin ") +
                      clash->name + " (" + clash->at.text() + "), and " + pin.shown() + " is " +
                      describe(*o) + ": a signal has one output pin, or I/O pins and no output",
                  "give " + pin.name + " a signal of its own");
        else if (o->direction == "out")
          writer = &pin;
        else if (o->direction == "io" && io == nullptr)
          io = &pin;
      }
    }
  }

  void setp_refused() {
    for (const auto& s : design_.settings()) {
      const std::string shown = NameUse{s.at, s.name, s.written}.shown();
      const auto o = object_of(s.name);
      if (o && !o->settable()) {
        refused(s.at, "setp-not-writable",
                "setp " + shown + ": it is " + (o->is_param() ? "a read-only param" : "an output pin") +
                    " (" + describe(*o) + "), which setp cannot set",
                o->is_param() ? "delete this line"
                              : "delete this line; read it with getp, or net it to what needs it");
      } else if (!s.linked_to.empty()) {
        refused(s.at, "setp-linked-pin",
                "setp " + shown + ": the pin is on signal " + s.linked_to +
                    " by then, and setp sets only a pin on no signal",
                "sets " + s.linked_to + " " + s.value + " (the signal's value), or setp before the net");
      }
    }
  }

  void sets_refused() {
    for (const auto& v : design_.signal_values()) {
      const auto& sig = design_.signals().at(v.signal);
      if (!v.signal_existed) {
        // Made later in these files: sets came too early. Made nowhere here: another file of
        // the configuration may make it, which is not judged.
        if (sig.pins.empty() && sig.declared_type.empty()) continue;
        refused(v.at, "sets-signal",
                "sets " + v.signal +
                    ": no net or newsig has made this signal by then (sets makes none; it is made at " +
                    sig.first.text() + ")",
                "move this line after the net or newsig that makes " + v.signal);
        continue;
      }
      for (std::size_t i = 0; i < v.pins_before && i < sig.pins.size(); ++i) {
        const auto o = object_of(sig.pins[i].name);
        if (!o || o->direction != "out") continue;
        refused(v.at, "sets-signal",
                "sets " + v.signal + ": the signal has the writer " + sig.pins[i].name + " (" +
                    sig.pins[i].at.text() + "), which sets its value",
                "delete this line, or take " + sig.pins[i].name + " off the signal");
        break;
      }
    }
  }

  void signal_type_names() {
    static const std::set<std::string> kTypes{"bit", "float", "s32", "u32"};
    for (const auto& [name, sig] : design_.signals())
      if (!sig.declared_type.empty() && kTypes.count(sig.declared_type) == 0)
        refused(sig.first, "signal-type",
                "newsig " + name + " " + sig.declared_type + ": HAL has no type '" + sig.declared_type +
                    "' (halcmd: \"Unknown signal type\")",
                "use bit, float, s32 or u32");
  }

  // A function of bldc or pid runs in one thread, once: halcmd refuses a second addf.
  void function_added_twice() {
    std::map<std::string, SourceLine> first;
    for (const auto& f : design_.functions()) {
      const auto b = split_bldc(f.name);
      const auto instance = instance_of(f.name);
      const bool known = (b && b->rest.empty()) ||
                         (instance && std::find(instance->functions.begin(), instance->functions.end(),
                                                instance->rest) != instance->functions.end());
      if (!known) continue;
      const auto [it, fresh] = first.emplace(f.name, f.at);
      if (fresh) continue;
      refused(f.at, "function-added-twice",
              "addf " + f.name + ": it is already added at " + it->second.text() +
                  ", and it may run in one thread, once (halcmd: \"may only be added to one thread\")",
              "delete this addf");
    }
  }

  // ---- names no component makes

  void unknown_names() {
    for (const auto& use : design_.names()) {
      const auto instance = instance_of(use.name);
      if (!instance || instance->judged_elsewhere || instance->objects.count(instance->rest) != 0 ||
          std::find(instance->functions.begin(), instance->functions.end(), instance->rest) !=
              instance->functions.end())
        continue;
      unknown_name(use, *instance);
    }
  }

  void unknown_name(const NameUse& use, const Instance& instance) {
    const auto close = nearest(instance.rest, instance.objects, instance.functions);
    const std::string prefix = use.name.substr(0, use.name.size() - instance.rest.size());
    add(use.at, LintSeverity::Error, "unknown-name",
        use.shown() + ": " + instance.kind + " has no pin, param or function '" + instance.rest +
            "' (halcmd finds no such name)" +
            (close.empty() ? std::string() : "; did you mean " + either_of(close, prefix) + "?"),
        close.size() == 1 ? "write " + prefix + close.front()
                          : "use a name " + instance.kind + " makes (docs/linuxcnc-hal.md; halcmd show pin)");
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

  // "NAME.in" when `pin` is the output of an instance of `loadrt biquad` (names=, or count=
  // as biquad.N).
  std::optional<std::string> biquad_input_of(const std::string& pin) const {
    const auto* biquad = design_.module("biquad");
    if (biquad == nullptr || pin.size() < 4 || pin.compare(pin.size() - 4, 4, ".out") != 0)
      return std::nullopt;
    const std::string instance = pin.substr(0, pin.size() - 4);
    const auto names = biquad->args.find("names");
    const bool ours = names != biquad->args.end()
                          ? std::ranges::count(split_commas(names->second), instance) > 0
                          : std::regex_match(instance, std::regex(R"(^biquad\.[0-9]+$)"));
    if (!ours) return std::nullopt;
    return instance + ".in";
  }

  // The pid instances whose output reaches `pin` directly, through a bldc (value -> out) or
  // through a biquad (in -> out). A file may loop a bldc back on itself (its out netted to its
  // own value): each is followed once.
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
        // A filter on the way (i20 hal --notch's biquad) passes the command on: follow its input.
        if (const auto in = biquad_input_of(p.name); in && followed.insert(*in).second)
          pending.push_back(*in);
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
      if (rule == nullptr) {
        unknown_name(use, *instance_of(use.name));
        continue;
      }
      add(use.at, LintSeverity::Error, "bldc-cfg",
          use.name + " does not exist: bldc." + std::to_string(b->index) + " is loaded with cfg=" +
              instance->cfg + ", and '" + b->rest + "' exists only with " + rule_condition(*rule),
          "delete this line, or change the cfg at " + instance->loaded_at.text());
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

  // A fault pin hostmot2 makes (or its -not twin): a misspelt one reaches nothing.
  bool is_fault_pin(const std::string& rest) const {
    const auto& faults = names_.i20_fault_pins();
    const auto& twin = names_.bit_pin_twin_suffix();
    return std::any_of(faults.begin(), faults.end(),
                       [&](const auto& f) { return rest == f || rest == f + twin; });
  }

  void fault_pins() {
    for (const auto& device : devices_) {
      bool reaches = false;
      for (const auto& use : design_.names()) {
        const auto name = split_8i20(use.name);
        if (name && name->device == device.name && is_fault_pin(name->rest) && design_.connected(use.name))
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

int lint_exit_code(const std::vector<LintFinding>& findings) {
  if (std::any_of(findings.begin(), findings.end(), [](const auto& f) { return f.refused_by_halcmd; }))
    return 2;
  return findings.empty() ? 0 : 1;
}

std::string to_string(const LintFinding& finding) {
  std::string out = finding.at.text() + ": " +
                    (finding.severity == LintSeverity::Error ? "error" : "warning") + ": " + finding.message;
  if (!finding.fix.empty()) out += " (fix: " + finding.fix + ")";
  return out;
}

}  // namespace i20::linuxcnc
