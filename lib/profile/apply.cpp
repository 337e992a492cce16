#include "profile/apply.hpp"

#include <algorithm>
#include <array>
#include <exception>

#include "params/value.hpp"
#include "profile/backup.hpp"
#include "profile/error.hpp"
#include "profile/save.hpp"
#include "profile/validate.hpp"

namespace i20::profile {
namespace {

// Working names of the parameters the cross-parameter rules look at.
constexpr std::array<const char*, 9> kRuleParams{
    "BRAKEONV", "BRAKEOFFV", "BUSOVERV", "BUSUNDERV", "MAXCURRENT", "KQP", "KDP", "KQI", "KDI"};

struct ReadOne {
  std::optional<std::int64_t> value;
  std::string error;
};

class Applier {
 public:
  Applier(const Profile& profile, const params::ParamDb& db, CardAccess& card, const ApplyOptions& options,
          ApplyResult& result)
      : profile_(profile), db_(db), card_(card), options_(options), result_(result) {}

  void run() {
    result_.card = describe_card();
    try {
      writes_ = cell_writes(profile_, db_);
    } catch (const Error& e) {
      return refuse(e.what());
    }
    if (!read_card()) return;
    result_.plan = make_plan(profile_, db_, snapshot_);  // shown even when refused
    if (!check()) return;
    if (options_.dry_run) return finish(Outcome::DryRun);
    if (result_.plan.empty()) return finish(Outcome::NothingToDo);
    if (!device_accepts() || !backup()) return;
    auto [touched, failure] = write_plan();
    if (failure.empty()) failure = verify();
    if (!failure.empty()) return roll_back(touched, failure);
    finish(Outcome::Applied);
    result_.reset_needed = result_.plan.reset_needed;
    if (options_.reset && result_.plan.reset_needed) reset_card();
  }

 private:
  // --- before any write
  std::string describe_card() {
    try {
      return card_.describe();
    } catch (const std::exception& e) {
      return std::string("unidentified card (") + e.what() + ")";
    }
  }

  bool read_card() {
    std::vector<std::string> names;
    for (const auto& w : writes_) names.push_back(w.cell);
    try {
      snapshot_ = card_.read(names);
    } catch (const std::exception& e) {
      refuse(std::string("cannot read the card's current values: ") + e.what());
      return false;
    }
    for (const auto& name : names)
      if (!snapshot_.contains(name)) {
        refuse("the card did not return a value for " + name);
        return false;
      }
    read_context();
    return true;
  }

  // The other values the rules compare against. Not required: a cell that cannot be read
  // is judged by its database default instead, as validate() does without a card.
  void read_context() {
    std::vector<std::string> names;
    for (const char* base : kRuleParams) {
      const params::Param* p = db_.find(base);
      if (!p) continue;
      for (const auto& cell : {p->name, p->twin})
        if (!cell.empty() && db_.find(cell) && !snapshot_.contains(cell)) names.push_back(cell);
    }
    try {
      for (const auto& [name, raw] : card_.read(names)) snapshot_[name] = raw;
      return;
    } catch (const std::exception&) {
      // One unreadable cell fails the batch: take the others one by one.
    }
    for (const auto& name : names) {
      const auto one = read_one(name);
      if (one.value) snapshot_[name] = *one.value;
    }
  }

  bool check() {
    const ValidationContext context{&snapshot_, options_.force};
    result_.findings = validate(profile_, db_, context);
    if (options_.reset) reset_conflicts();
    if (has_errors(result_.findings)) {
      refuse("the profile has errors; nothing was written");
      return false;
    }
    return true;
  }

  // A reset loads every working parameter from the EEPROM, so a working value that the
  // profile does not also write to the EEPROM would be lost at once.
  void reset_conflicts() {
    RawValues nv_written;
    for (const auto& w : writes_)
      if (db_.get(w.cell).is_nv()) nv_written[w.cell] = w.raw;
    for (const auto& w : writes_) {
      const params::Param& p = db_.get(w.cell);
      if (p.is_nv()) continue;
      const auto twin = nv_written.find(p.twin);
      if (twin == nv_written.end() || twin->second != w.raw)
        result_.findings.push_back({Severity::Error, p.name, "reset-discards-working",
                                    "a reset would replace the working " + p.name +
                                        " with its EEPROM value; use target both, or apply without reset",
                                    profile_.where(profile_.settings[w.setting])});
    }
  }

  // The device layer's own rules, asked for every write before the first one is sent.
  bool device_accepts() {
    for (const auto& step : result_.plan.steps) {
      try {
        card_.check_write(step.cell, step.profile_raw);
      } catch (const std::exception& e) {
        refuse("the card would refuse " + step.cell + " = " + step.profile_text + ": " + e.what() +
               "; nothing was written");
        return false;
      }
    }
    return true;
  }

  bool backup() {
    std::vector<std::string> names;
    for (const auto& w : writes_) names.push_back(w.cell);
    SaveOptions save;
    save.name = "backup before " + profile_.name;
    save.notes =
        "The card's values before applying " + profile_.source + ". Apply this file to restore them.";
    save.when = options_.when;
    try {
      const Profile before = profile_from_values(snapshot_, names, db_, result_.card, save);
      result_.backup = write_backup(before, db_, options_.backup_dir, profile_.name, options_.when);
    } catch (const std::exception& e) {
      refuse(std::string("cannot write the backup, so nothing was written: ") + e.what());
      return false;
    }
    return true;
  }

  // --- writing
  // How many cells were touched (a failed one included: its state is unknown), and why
  // the writing stopped, if it did.
  struct Progress {
    std::size_t touched = 0;
    std::string failure;
  };

  Progress write_plan() {
    const auto& steps = result_.plan.steps;
    for (std::size_t i = 0; i < steps.size(); ++i) {
      const WriteRecord record = write_one(steps[i].cell, steps[i].profile_raw);
      result_.writes.push_back(record);
      if (!record.ok) return {i + 1, "writing " + record.cell + " failed: " + record.error};
    }
    return {steps.size(), {}};
  }

  std::string verify() {
    std::vector<std::string> names;
    for (const auto& step : result_.plan.steps) names.push_back(step.cell);
    RawValues now;
    try {
      now = card_.read(names);
    } catch (const std::exception& e) {
      return std::string("reading back the written values failed: ") + e.what();
    }
    std::string mismatches;
    for (const auto& step : result_.plan.steps) {
      const auto it = now.find(step.cell);
      if (it == now.end() || it->second != step.profile_raw)
        mismatches += (mismatches.empty() ? "" : ", ") + step.cell + " reads " +
                      (it == now.end() ? std::string("nothing") : text(step.cell, it->second)) +
                      " instead of " + step.profile_text;
    }
    if (!mismatches.empty()) return "verify failed: " + mismatches;
    for (const auto& step : result_.plan.steps)
      result_.cells.push_back(state_of(step, ReadOne{now.at(step.cell), {}}));
    return {};
  }

  // --- restoring
  // Undo in reverse order: the reverse of a safe path is a safe path. A cell that still
  // holds its original value is not written again (EEPROM wear).
  void roll_back(std::size_t touched, const std::string& failure) {
    result_.reason = failure;
    const auto& steps = result_.plan.steps;
    for (std::size_t i = touched; i-- > 0;) {
      const auto& step = steps[i];
      const std::int64_t original = *step.card_raw;
      if (read_one(step.cell).value == original) {
        result_.rollback.push_back({step.cell, original, step.card_text, true, true, {}});
        continue;
      }
      result_.rollback.push_back(write_one(step.cell, original));
    }
    result_.cells.clear();
    bool restored = true;
    for (std::size_t i = 0; i < touched; ++i) {
      result_.cells.push_back(state_of(steps[i], read_one(steps[i].cell)));
      restored = restored && result_.cells.back().status == CellStatus::Original;
    }
    result_.outcome = restored ? Outcome::RolledBack : Outcome::RollbackFailed;
    if (!restored) result_.reason += "; restoring the backup values failed, see the cell states";
  }

  void reset_card() {
    try {
      card_.reset();
      result_.reset_done = true;
      result_.reset_needed = false;
    } catch (const std::exception& e) {
      result_.reset_error = std::string("reset failed: ") + e.what();
      return;
    }
    // The EEPROM must still hold what was verified (a reset must not have lost it).
    for (const auto& step : result_.plan.steps) {
      if (!step.nv) continue;
      const auto one = read_one(step.cell);
      if (one.value != step.profile_raw)
        result_.reset_error += (result_.reset_error.empty() ? "after the reset " : ", ") + step.cell +
                               " reads " +
                               (one.value ? text(step.cell, *one.value) : "unknown (" + one.error + ")");
    }
  }

  // --- helpers
  WriteRecord write_one(const std::string& cell, std::int64_t value) {
    WriteRecord record{cell, value, text(cell, value), false, false, {}};
    try {
      card_.write(cell, value);
      record.ok = true;
    } catch (const std::exception& e) {
      record.error = e.what();
    }
    return record;
  }

  ReadOne read_one(const std::string& cell) {
    try {
      const RawValues values = card_.read({cell});
      const auto it = values.find(cell);
      if (it == values.end()) return {std::nullopt, "the card returned no value"};
      return {it->second, {}};
    } catch (const std::exception& e) {
      return {std::nullopt, e.what()};
    }
  }

  CellState state_of(const DiffRow& step, const ReadOne& now) const {
    CellState s;
    s.cell = step.cell;
    s.original = *step.card_raw;
    s.intended = step.profile_raw;
    s.actual = now.value;
    s.actual_text = now.value ? text(step.cell, *now.value) : "unknown";
    s.error = now.error;
    if (!now.value)
      s.status = CellStatus::Unknown;
    else if (*now.value == s.intended)
      s.status = CellStatus::Intended;
    else if (*now.value == s.original)
      s.status = CellStatus::Original;
    else
      s.status = CellStatus::Other;
    return s;
  }

  std::string text(const std::string& cell, std::int64_t raw) const {
    return params::format_engineering(db_.get(cell), raw);
  }

  void refuse(const std::string& reason) {
    result_.outcome = Outcome::Refused;
    result_.reason = reason;
  }
  void finish(Outcome outcome) { result_.outcome = outcome; }

  const Profile& profile_;
  const params::ParamDb& db_;
  CardAccess& card_;
  const ApplyOptions& options_;
  ApplyResult& result_;
  std::vector<CellWrite> writes_;
  RawValues snapshot_;
};

}  // namespace

const char* to_string(Outcome outcome) {
  switch (outcome) {
    case Outcome::Refused: return "refused";
    case Outcome::DryRun: return "dry-run";
    case Outcome::NothingToDo: return "nothing-to-do";
    case Outcome::Applied: return "applied-and-verified";
    case Outcome::RolledBack: return "rolled-back-and-verified";
    case Outcome::RollbackFailed: return "rollback-failed";
  }
  return "?";
}

const char* to_string(CellStatus status) {
  switch (status) {
    case CellStatus::Intended: return "intended";
    case CellStatus::Original: return "original";
    case CellStatus::Other: return "other";
    case CellStatus::Unknown: return "unknown";
  }
  return "?";
}

ApplyResult apply(const Profile& profile, const params::ParamDb& db, CardAccess& card,
                  const ApplyOptions& options) {
  ApplyResult result;
  Applier(profile, db, card, options, result).run();
  return result;
}

}  // namespace i20::profile
