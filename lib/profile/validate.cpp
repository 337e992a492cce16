// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/validate.hpp"

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <map>
#include <optional>

#include "params/value.hpp"
#include "profile/amp_limits.hpp"
#include "profile/effective.hpp"
#include "profile/error.hpp"
#include "profile/step_response.hpp"

namespace i20::profile {
namespace {

using params::Space;

// Limits the manual states (sections MOTOR BRAKE, OPERATE MODE BAUD RATE, BRAKEONV and
// BRAKEOFFV); the card's current and bus limits are in profile/amp_limits.hpp.
constexpr double kFixedBrakeOnV = 385.0;    // fixed brake-on that protects the module
constexpr std::int64_t kMaxBaudIndex = 11;  // OPERATE MODE BAUD RATE: the table's last index
constexpr double kBrakeHysteresisV = 20.0;  // "BRAKEOFFV be set 20V lower than BRAKEON"
constexpr double kBrakeHysteresisToleranceV = 5.0;
// Servo motors are commonly rated for about three times their continuous current as peak.
constexpr double kTypicalPeakRatio = 3.0;

std::string volts(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f V", v);
  return buf;
}

std::string amps(double a) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f A", a);
  return buf;
}

// A threshold the measured bus makes unsafe: at or below it (`unsafe_at_or_below`), or at
// or above it. Manual: FAULT CONDITIONS (BUSLOVFAULT, BUSHIVFAULT), MOTOR BRAKE and
// BRAKEONV/BRAKEOFFV (DRIVE PARAMETER SETUP); BUSUNDERVMAX: docs/facts.md s2.
struct BusRule {
  const char* base;  // the working name; the NV twin is judged by the same rule
  bool unsafe_at_or_below;
  const char* rule;
  const char* consequence;
};
constexpr BusRule kBusRules[] = {
    {"BUSOVERV", true, "bus-measured-overvoltage", "the drive would fault with bus over-voltage"},
    {"BRAKEONV", true, "bus-measured-brake",
     "the brake resistor would switch on and take the supply's power"},
    {"BRAKEOFFV", true, "bus-measured-brake-off",
     "after one braking event the brake would never switch off again (its off threshold is below the "
     "supply) and the resistor would take the supply's power"},
    {"BUSUNDERV", false, "bus-measured-undervoltage", "the drive would fault with bus under-voltage"},
    {"BUSUNDERVMAX", false, "bus-measured-undervoltage-max",
     "a bus under-voltage fault could never clear (the bus must rise above this level again)"},
};

// The manual (MOTOR POWER): motor power ranges from 35 to 400 V, and "all communication to
// the 8I20 will work down to 0V motor power". A bus below 35 V is a supply that is off or
// not up yet (setup on the bench with logic power only): it says nothing about the supply
// the under-voltage thresholds will meet, so they are not judged against it.
constexpr double kLowestMotorSupplyV = 35.0;

const BusRule* bus_rule_of(const params::Param& p) {
  const std::string base = p.is_nv() && !p.twin.empty() ? p.twin : p.name;
  for (const auto& rule : kBusRules)
    if (base == rule.base) return &rule;
  return nullptr;
}

class Checker {
 public:
  Checker(const Profile& profile, const params::ParamDb& db, const ValidationContext& context,
          std::vector<Finding>& out)
      : profile_(profile), db_(db), context_(context), out_(out) {}

  // Only what needs no card values: each value on its own.
  void run_values() {
    try {
      entry_rules();
      card_limits();
    } catch (const ProfileError& e) {
      out_.push_back({Severity::Error, e.key(), e.rule(), e.reason(), e.where()});
    } catch (const params::UnknownParameter& e) {
      out_.push_back({Severity::Error, "", "unknown-parameter", e.what(), profile_.source});
    }
  }

  void run() {
    std::optional<EffectiveValues> ev;
    try {
      ev.emplace(profile_, db_, context_.card);
    } catch (const ProfileError& e) {
      out_.push_back({Severity::Error, e.key(), e.rule(), e.reason(), e.where()});
      return;
    } catch (const params::UnknownParameter& e) {  // a profile built in code, not loaded
      out_.push_back({Severity::Error, "", "unknown-parameter", e.what(), profile_.source});
      return;
    }
    ev_ = &*ev;
    entry_rules();
    card_limits();
    supply_limit();
    for (const Space space : {Space::Eeprom, Space::Ram})
      if (ev_->touches(space)) space_rules(space);
  }

 private:
  // --- per entry: what the database says about each cell written
  void entry_rules() {
    for (const auto& s : profile_.settings) {
      for (const auto& cell : cells_of(profile_, s, db_)) {
        const params::Param& p = db_.get(cell);
        if (!p.writable()) {
          add(Severity::Error, cell, "read-only",
              cell + " is read-only on the 8I20; a profile holds settings", &s);
          continue;
        }
        if (!p.guard.empty())
          add(context_.force ? Severity::Warning : Severity::Error, cell, "guarded",
              p.guard + (context_.force ? " (forced)" : ""), &s, overridden_by_force());
        try {
          params::check_range(p, s.raw);
        } catch (const params::ValueError& e) {
          add(Severity::Error, cell, "range", e.what(), &s);
        }
      }
    }
  }

  // Limits of the card itself, judged whatever range a database overlay gives: an overlay
  // can place a parameter, not make the hardware stronger.
  void card_limits() {
    for (const auto& s : profile_.settings)
      for (const auto& cell : cells_of(profile_, s, db_)) {
        const params::Param& p = db_.get(cell);
        const std::string base = p.is_nv() && !p.twin.empty() ? p.twin : p.name;
        const double engineering = static_cast<double>(s.raw) * p.scale;
        const std::string text = cell + " " + params::format_engineering(p, s.raw);
        if ((base == "BAUDRATE" || p.name == "NVBAUDRATE") && (s.raw < 0 || s.raw > kMaxBaudIndex))
          add(Severity::Error, cell, "baud-index",
              cell + " " + std::to_string(s.raw) + " is not an index of the manual's baud rate table (0..11)",
              &s);
        if (base == "MAXCURRENT" && engineering > kAmpMaxCurrentA + 1e-9)
          add(Severity::Error, cell, "maxcurrent-card",
              text + " (profile) is above the 8I20's " + limit_text(kAmpMaxCurrentA, "A") + " RMS rating",
              &s);
        if (base == "BRAKEONV" && engineering > kFixedBrakeOnV + 1e-9)
          add(Severity::Error, cell, "brake-on-limit",
              text + " (profile) is above the fixed 385 V brake-on that protects the 8I20 module", &s);
      }
  }

  // Thresholds the profile writes in this space, against the bus the card measures now.
  void measured_bus_rules() {
    if (!context_.measured_bus_v) return;
    RawValues cells;
    std::map<std::string, const Setting*> settings;
    for (const auto& rule : kBusRules)
      if (const auto v = value(rule.base); v && v->origin == Origin::Profile) {
        cells[v->param->name] = v->raw;
        settings[v->param->name] = v->setting;
      }
    for (auto& f : measured_bus_findings(cells, *context_.measured_bus_v, db_, context_.force)) {
      f.where = profile_.where(*settings.at(f.key));
      out_.push_back(std::move(f));
    }
  }

  void supply_limit() {
    const auto bus = profile_.supply.bus_voltage_v;
    if (bus && *bus > amp_max_bus_v())
      add(Severity::Error, "supply.bus_voltage", "bus-card-limit",
          "a " + volts(*bus) + " bus is above the 8I20's " + limit_text(amp_max_bus_v(), "V") +
              " motor supply rating",
          nullptr);
  }

  // --- cross-parameter rules, judged on what one space (EEPROM or working) will hold
  void space_rules(Space space) {
    space_ = space;
    brake_rules();
    voltage_rules();
    current_rules();
    gain_match("KQP", "KDP", "kp-match");
    gain_match("KQI", "KDI", "ki-match");
    supply_rules();
    measured_bus_rules();
    current_loop_rules();
  }

  // The PI gains of both axes, simulated on the profile's own motor by the tuning model
  // (lib/profile/step_response.hpp): gains the model calls unstable are refused, as
  // `i20 tune` refuses to write them. Needs the motor's R and L and a bus voltage.
  void current_loop_rules() {
    const auto& motor = profile_.motor;
    const auto bus = profile_.supply.bus_voltage_v ? profile_.supply.bus_voltage_v : context_.measured_bus_v;
    if (!motor.phase_resistance_ohm || !motor.phase_inductance_h || !bus) return;
    const auto max = value("MAXCURRENT");
    for (const auto& [kp_name, ki_name] : {std::pair{"KQP", "KQI"}, std::pair{"KDP", "KDI"}}) {
      const auto kp = value(kp_name), ki = value(ki_name);
      if (!max || !kp || !ki || !touched({max, kp, ki}) || max->raw <= 0 || kp->raw <= 0) continue;
      LoopVerdict verdict;
      try {
        verdict = judge_gains({*motor.phase_resistance_ohm, *motor.phase_inductance_h}, max->engineering(),
                              *bus, kp->raw, ki->raw);
      } catch (const TuneError&) {
        continue;  // non-physical motor data is the loader's to refuse
      }
      if (verdict.acceptable) continue;
      add(context_.force ? Severity::Warning : Severity::Error, pick({kp, ki, max}), "loop-unstable",
          kp->describe() + " with " + ki->describe() + " on this motor: " + verdict.reason +
              (context_.force ? " (forced)" : "; lower the gains (i20 tune)"),
          overridden_by_force());
    }
  }

  void brake_rules() {
    const auto on = value("BRAKEONV");
    const auto off = value("BRAKEOFFV");
    if (!on || !off || !touched({on, off})) return;
    if (off->raw >= on->raw) {
      add(Severity::Error, pick({off, on}), "brake-order",
          off->describe() + " must be below " + on->describe() +
              ": the manual requires BrakeOn always higher than BrakeOff");
      return;
    }
    const double gap = on->engineering() - off->engineering();
    if (std::abs(gap - kBrakeHysteresisV) > kBrakeHysteresisToleranceV)
      add(Severity::Warning, pick({off, on}), "brake-hysteresis",
          off->describe() + " is " + volts(gap) + " below " + on->describe() +
              "; the manual suggests about 20 V (less makes the brake chatter, more dumps more energy)");
  }

  void voltage_rules() {
    const auto under = value("BUSUNDERV");
    const auto over = value("BUSOVERV");
    const auto on = value("BRAKEONV");
    undervoltage_pair(under, value("BUSUNDERVMAX"));
    if (under && over && touched({under, over}) && under->raw >= over->raw)
      add(Severity::Error, pick({under, over}), "undervoltage-below-overvoltage",
          under->describe() + " must be below " + over->describe() + ": every bus voltage would be a fault");
    if (on && over && touched({on, over}) && on->raw >= over->raw)
      add(Severity::Warning, pick({on, over}), "brake-below-overvoltage",
          on->describe() + " is not below " + over->describe() +
              ": the over-voltage fault trips before the brake resistor takes the regenerated energy");
  }

  // The EEPROM holds two under-voltage thresholds, the low one (NVBUSUNDERV, LinuxCNC's
  // nvbusundervmin) and the high one (NVBUSUNDERVMAX, nvbusundervmax); docs/facts.md s2:
  // the low one must stay below the high one, in both spaces.
  void undervoltage_pair(const std::optional<Effective>& under, const std::optional<Effective>& under_max) {
    if (!under) return;
    if (under_max) {
      if (touched({under, under_max}) && under->raw >= under_max->raw)
        add(Severity::Error, pick({under, under_max}), "undervoltage-pair-order",
            under->describe() + " must be below " + under_max->describe() +
                ": the low under-voltage threshold (LinuxCNC's nvbusundervmin) must stay below the high one "
                "(nvbusundervmax)");
      return;
    }
    // Raised above the factory low threshold with the high one unknown (no card, and no
    // published factory value): the pair may end up inverted, so it must be set too.
    std::optional<std::int64_t> factory = under->param->default_value;
    if (!factory && !under->param->twin.empty()) factory = db_.get(under->param->twin).default_value;
    const params::Param* p = db_.find("BUSUNDERVMAX");
    const std::string max_name = !p ? "BUSUNDERVMAX" : space_ == Space::Ram ? p->name : p->twin;
    if (under->origin == Origin::Profile && factory && under->raw > *factory)
      add(Severity::Error, *under, "undervoltage-pair-unknown",
          under->describe() + " is above the factory " + params::format_engineering(*under->param, *factory) +
              " and " + max_name +
              " (the high under-voltage threshold) is not known here: set it in the profile too, above " +
              under->param->name);
  }

  void current_rules() {
    const auto max = value("MAXCURRENT");
    if (!max) return;
    // The motor's ratings come from the profile, so they are judged whenever it touches this space.
    const MotorInfo& m = profile_.motor;
    const double amps_set = max->engineering();
    if (m.peak_current_a) {
      if (amps_set > *m.peak_current_a + 1e-9)
        add(Severity::Error, *max, "maxcurrent-motor",
            max->describe() + " is above the motor's peak rating of " + amps(*m.peak_current_a) +
                ": full-scale commands could demagnetise or overheat it");
    } else if (m.continuous_current_a) {
      const double cont = *m.continuous_current_a;
      if (amps_set > kTypicalPeakRatio * cont + 1e-9)
        add(Severity::Error, *max, "maxcurrent-motor",
            max->describe() + " is more than 3x the motor's continuous rating of " + amps(cont) +
                "; give motor.peak_current if the motor really takes it");
      else if (amps_set > cont + 1e-9)
        add(Severity::Warning, *max, "maxcurrent-motor",
            max->describe() + " is above the motor's continuous rating of " + amps(cont) +
                " and no peak rating is given; the host must keep the RMS current within the rating");
    }
  }

  void gain_match(const char* q, const char* d, const char* rule) {
    const auto qv = value(q);
    const auto dv = value(d);
    if (qv && dv && touched({qv, dv}) && qv->raw != dv->raw)
      add(Severity::Warning, pick({qv, dv}), rule,
          qv->describe() + " differs from " + dv->describe() + ": the manual says they are normally equal");
  }

  // Rules about the supply the profile says it is for (metadata bus_voltage).
  void supply_rules() {
    if (!profile_.supply.bus_voltage_v) return;
    const double bus = *profile_.supply.bus_voltage_v;
    const std::string bus_text = "the " + volts(bus) + " supply bus";
    if (const auto under = value("BUSUNDERV"); under && under->engineering() >= bus)
      add(Severity::Error, *under, "bus-above-undervoltage",
          under->describe() + " is not below " + bus_text + ": the drive would fault at its normal supply");
    if (const auto under_max = value("BUSUNDERVMAX"); under_max && under_max->engineering() >= bus)
      add(Severity::Error, *under_max, "bus-above-undervoltage-max",
          under_max->describe() + " is not below " + bus_text +
              ": a bus under-voltage fault could never clear at the normal supply");
    if (const auto over = value("BUSOVERV"); over && over->engineering() <= bus)
      add(Severity::Error, *over, "bus-below-overvoltage",
          over->describe() + " is not above " + bus_text + ": the drive would fault at its normal supply");
    if (const auto on = value("BRAKEONV"); on && on->engineering() <= bus) {
      add(Severity::Error, *on, "brake-above-bus",
          on->describe() + " is not above " + bus_text +
              ": the brake resistor would take the supply's power");
    } else if (const auto off = value("BRAKEOFFV"); off && off->engineering() < bus) {
      add(Severity::Warning, *off, "brake-off-above-bus",
          off->describe() + " is below " + bus_text +
              ": once on, the brake would not switch off until the supply sags");
    }
  }

  // --- helpers
  // The effective value of a working/NV pair in the space being checked, by working name.
  std::optional<Effective> value(const char* working_name) const {
    const params::Param* p = db_.find(working_name);
    if (!p) return std::nullopt;
    const std::string cell = space_ == Space::Ram ? p->name : p->twin;
    if (cell.empty() || !db_.find(cell)) return std::nullopt;
    return ev_->get(cell);
  }

  static bool touched(std::initializer_list<std::optional<Effective>> values) {
    for (const auto& v : values)
      if (v && v->origin == Origin::Profile) return true;
    return false;
  }

  // The value a finding is about: the first one the profile sets.
  static Effective pick(std::initializer_list<std::optional<Effective>> values) {
    for (const auto& v : values)
      if (v && v->origin == Origin::Profile) return *v;
    return **values.begin();
  }

  void add(Severity severity, const Effective& about, const char* rule, const std::string& message,
           Advice advice = Advice::None) {
    add(severity, about.param->name, rule, message, about.setting, advice);
  }
  void add(Severity severity, const std::string& key, const char* rule, const std::string& message,
           const Setting* setting, Advice advice = Advice::None) {
    out_.push_back(
        {severity, key, rule, message, setting ? profile_.where(*setting) : profile_.source, advice});
  }
  // An error that forcing turns into a warning says so; a forced one has nothing left to override.
  Advice overridden_by_force() const { return context_.force ? Advice::None : Advice::Force; }

  const Profile& profile_;
  const params::ParamDb& db_;
  const ValidationContext& context_;
  std::vector<Finding>& out_;
  const EffectiveValues* ev_ = nullptr;
  Space space_ = Space::Eeprom;
};

}  // namespace

std::vector<Finding> validate_values(const Profile& profile, const params::ParamDb& db, bool force) {
  std::vector<Finding> findings;
  const ValidationContext context{nullptr, force, std::nullopt};
  Checker(profile, db, context, findings).run_values();
  return findings;
}

std::vector<Finding> validate(const Profile& profile, const params::ParamDb& db,
                              const ValidationContext& context) {
  std::vector<Finding> findings;
  Checker(profile, db, context, findings).run();
  return findings;
}

std::vector<Finding> measured_bus_findings(const RawValues& cells, double measured_bus_v,
                                           const params::ParamDb& db, bool force) {
  std::vector<Finding> findings;
  const std::string bus = "the " + volts(measured_bus_v) + " the card measures on its bus now";
  for (const auto& [name, raw] : cells) {
    const params::Param* p = db.find(name);
    const BusRule* rule = p ? bus_rule_of(*p) : nullptr;
    if (!rule) continue;
    if (!rule->unsafe_at_or_below && measured_bus_v < kLowestMotorSupplyV) continue;
    const double v = static_cast<double>(raw) * p->scale;
    // "At" the bus within a thousandth of a count: 17000 x 0.01 V is 170 V, whatever the doubles say.
    const double at = 1e-3 * p->scale;
    const bool unsafe = rule->unsafe_at_or_below ? v <= measured_bus_v + at : v >= measured_bus_v - at;
    if (!unsafe) continue;
    const std::string when = p->is_nv() ? " from the next reset on" : " at once";
    findings.push_back({force ? Severity::Warning : Severity::Error, p->name, rule->rule,
                        p->name + " " + params::format_engineering(*p, raw) + " is at or " +
                            (rule->unsafe_at_or_below ? "below " : "above ") + bus + ": " +
                            rule->consequence + when +
                            (force ? " (forced)" : ", unless the supply will change first"),
                        "", force ? Advice::None : Advice::Force});
  }
  return findings;
}

}  // namespace i20::profile
