// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/transaction.hpp"

#include <algorithm>
#include <exception>
#include <set>

#include "ops/reset.hpp"
#include "params/value.hpp"
#include "profile/backup.hpp"
#include "profile/error.hpp"
#include "profile/save.hpp"
#include "profile/validate.hpp"

namespace i20::ops {
namespace {

using profile::DiffRow;
using profile::Severity;

struct ReadOne {
  std::optional<std::int64_t> value;
  std::string error;
  bool link_failed = false;  // the card did not answer (not: the address is no fact here)
};

class Transaction {
 public:
  Transaction(const profile::Profile& profile, const params::ParamDb& db, CellAccess& card,
              const TransactionOptions& options, TransactionResult& result)
      : profile_(profile), db_(db), card_(card), options_(options), result_(result) {}

  void run() {
    result_.card = describe_card();
    try {
      writes_ = profile::cell_writes(profile_, db_);
    } catch (const Error& e) {
      return stop(Outcome::BadInput, e.what());
    }
    if (interrupted_before("reading the card")) return;
    if (!read_card()) return;
    result_.plan = profile::make_plan(profile_, db_, snapshot_);  // shown even when refused
    // The device layer's rules too before a dry run ends: a dry run (and `profile validate`
    // against a card) is refused exactly when the real apply would be.
    if (!check() || !order_is_safe() || !device_accepts()) return;
    if (options_.on_plan) options_.on_plan(result_.plan);
    if (options_.dry_run) return finish(Outcome::DryRun);
    if (result_.plan.empty()) return nothing_to_do();
    if (!backup()) return;
    if (interrupted_before("writing")) return;
    auto [touched, failure] = write_plan();
    if (failure.empty() && !stop_requested()) failure = verify();
    // A stop that came during the last write or the read-back still undoes the change: the
    // command was not done yet, and "stop" must mean one thing wherever it lands.
    if (stop_requested() || !failure.empty()) return roll_back(touched, failure);
    finish(Outcome::Done);
    result_.reset_needed = result_.plan.reset_needed;
    if (options_.reset && result_.plan.reset_needed) reset_amp();
    copy_events();
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

  bool interrupted_before(const std::string& what) {
    if (!options_.cancel.requested()) return false;
    result_.interrupted = true;
    stop(Outcome::Interrupted,
         "interrupted (" + options_.cancel.cause() + ") before " + what + ": nothing was written");
    return true;
  }

  // Has a stop been asked for (SIGINT, SIGTERM, SIGHUP)? Remembered in the result.
  bool stop_requested() {
    if (options_.cancel.requested()) result_.interrupted = true;
    return result_.interrupted;
  }

  bool read_card() {
    std::vector<std::string> names;
    for (const auto& w : writes_) names.push_back(w.cell);
    // In the same read: the working twins of the EEPROM cells (working_before).
    std::vector<std::string> with_twins = names;
    for (const auto& w : writes_)
      if (const params::Param& p = db_.get(w.cell); p.is_nv() && !p.twin.empty() && db_.find(p.twin) &&
                                                    std::ranges::find(with_twins, p.twin) == with_twins.end())
        with_twins.push_back(p.twin);
    try {
      asked_.insert(with_twins.begin(), with_twins.end());
      snapshot_ = card_.read(with_twins);
      for (const auto& name : with_twins)
        if (const params::Param& p = db_.get(name); !p.is_nv() && snapshot_.contains(name))
          result_.working_before[name] = snapshot_.at(name);
    } catch (const std::exception& e) {
      stop(Outcome::Failed,
           std::string("cannot read the card's current values, so nothing was written: ") + e.what());
      return false;
    }
    for (const auto& name : names)
      if (!snapshot_.contains(name)) {
        stop(Outcome::Refused,
             "the card cannot read " + name +
                 " as a fact: its address is not confirmed for this card's firmware; run `i20 discover`",
             Advice::AllowUnverified);
        return false;
      }
    return read_context();
  }

  // The other values the rules compare against, and the measured bus. A cell whose address
  // is not a fact on this firmware is judged by its database default, as validate() does
  // without a card; a cell the card fails to answer for stops the transaction, since the
  // rules (the measured-bus ones above all) would otherwise be judged on a guess.
  bool read_context() {
    std::vector<std::string> names;
    for (const auto& base : rule_parameters()) {
      const params::Param* p = db_.find(base);
      if (!p) continue;
      for (const auto& cell : {p->name, p->twin})
        if (!cell.empty() && db_.find(cell) && !snapshot_.contains(cell)) names.push_back(cell);
    }
    if (db_.find("BUSV")) names.push_back("BUSV");
    asked_.insert(names.begin(), names.end());  // a link failure below stops the transaction
    try {
      for (const auto& [name, raw] : card_.read(names)) context_[name] = raw;
    } catch (const std::exception&) {
      // One unreadable cell fails the batch: take the others one by one.
      for (const auto& name : names) {
        const auto one = read_one(name);
        if (one.value) context_[name] = *one.value;
        if (one.link_failed) {
          stop(Outcome::Failed,
               "cannot read " + name +
                   ", which the safety rules compare against, so nothing was written: " + one.error);
          return false;
        }
      }
    }
    for (const auto& [name, raw] : context_)
      if (name != "BUSV") snapshot_.try_emplace(name, raw);
    return true;
  }

  bool check() {
    profile::ValidationContext context{&snapshot_, options_.force, std::nullopt};
    if (const auto bus = context_.find("BUSV"); bus != context_.end())
      context.measured_bus_v = static_cast<double>(bus->second) * db_.get("BUSV").scale;
    result_.findings = profile::validate(profile_, db_, context);
    if (options_.reset) reset_conflicts();
    if (options_.reset)
      add_reset_findings(result_.findings, db_, card_, options_.force, profile_, read_already());
    if (profile::has_errors(result_.findings)) {
      stop(Outcome::Refused, first_error() + "; nothing was written", first_error_advice());
      return false;
    }
    return true;
  }

  // The first error in full, the others by rule, so a one-line report still names them all.
  std::string first_error() const {
    std::vector<const profile::Finding*> errors;
    for (const auto& f : result_.findings)
      if (f.severity == Severity::Error) errors.push_back(&f);
    const auto& first = *errors.front();
    std::string text = first.key.empty() ? first.message : first.key + ": " + first.message;
    text += " [" + first.rule + "]";
    if (errors.size() > 1) {
      text += " (and " + std::to_string(errors.size() - 1) + " more:";
      for (std::size_t i = 1; i < errors.size(); ++i)
        text += " " + errors[i]->key + " [" + errors[i]->rule + "]";
      text += ")";
    }
    return text;
  }

  // What read_card() and read_context() read, for the reset's judgement: it reads only the
  // other cells, so each is read once. Every link failure there stopped the transaction, so an
  // asked cell without a value is no fact on this firmware, never an unanswered one.
  ReadAlready read_already() const {
    ReadAlready already{snapshot_, asked_};
    if (const auto bus = context_.find("BUSV"); bus != context_.end()) already.values["BUSV"] = bus->second;
    return already;
  }

  // What overrides the refusal: what overrides every error (forcing lifts the guarded and
  // measured-bus rules, but not the manual's order), else nothing.
  Advice first_error_advice() const {
    std::optional<Advice> common;
    for (const auto& f : result_.findings) {
      if (f.severity != Severity::Error) continue;
      if (common && *common != f.advice) return Advice::None;
      common = f.advice;
    }
    return common.value_or(Advice::None);
  }

  // Belt and braces over the plan's ordering: every intermediate state must keep the
  // threshold pairs in order, or nothing is written.
  bool order_is_safe() {
    const std::string unsafe = profile::unsafe_step(result_.plan, db_, snapshot_);
    if (unsafe.empty()) return true;
    stop(Outcome::Refused, "no safe write order: " + unsafe + "; nothing was written");
    return false;
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

  // Nothing differs, but a reset may still be pending: NV cells whose working twin holds
  // something else are not live yet.
  void nothing_to_do() {
    finish(Outcome::NothingToDo);
    if (!options_.reset) return;
    RawValues values;
    for (const auto& row : result_.plan.unchanged) {
      const params::Param& p = db_.get(row.cell);
      if (!p.is_nv() || p.twin.empty()) continue;
      values[row.cell] = row.profile_raw;
      if (const auto live = read_one(p.twin); live.value) values[p.twin] = *live.value;
    }
    result_.reset_needed = !pending_nv_values(db_, values).empty();
    if (result_.reset_needed) reset_amp();
    copy_events();
  }

  // The device layer's own rules, asked for every write before the first one is sent.
  bool device_accepts() {
    for (const auto& step : result_.plan.steps) {
      try {
        card_.check_write(step.cell, step.profile_raw);
      } catch (const std::exception& e) {
        const auto* error = dynamic_cast<const Error*>(&e);
        stop(Outcome::Refused,
             "the card would refuse " + step.cell + " = " + step.profile_text + ": " + e.what() +
                 "; nothing was written",
             error ? error->advice() : Advice::None);
        return false;
      }
    }
    return true;
  }

  bool backup() {
    if (!options_.backup_dir) return true;
    std::vector<std::string> names;
    for (const auto& w : writes_) names.push_back(w.cell);
    profile::SaveOptions save;
    save.name = "backup before " + profile_.name;
    save.notes =
        "The card's values before applying " + profile_.source + ". Apply this file to restore them.";
    save.when = options_.when;
    save.origin = options_.backup_origin;
    try {
      const auto before = profile::profile_from_values(snapshot_, names, db_, result_.card, save);
      const std::string label = options_.backup_label.empty() ? profile_.name : options_.backup_label;
      result_.backup = profile::write_backup(before, db_, *options_.backup_dir, label, options_.when);
    } catch (const std::exception& e) {
      stop(Outcome::OutputLost, std::string("cannot write the backup, so nothing was written: ") + e.what());
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
      // A stop request between writes: stop here and restore what was written.
      if (i > 0 && stop_requested()) return {i, {}};
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
  // holds its original value is not written again (EEPROM wear). No stop request ends it.
  void roll_back(std::size_t touched, const std::string& failure) {
    card_.way_back();
    result_.reason = result_.interrupted && failure.empty()
                         ? "interrupted (" + options_.cancel.cause() + ") after " + std::to_string(touched) +
                               " of " + std::to_string(result_.plan.steps.size()) + " writes"
                         : failure;
    const auto& steps = result_.plan.steps;
    for (std::size_t i = touched; i-- > 0;) {
      const auto& step = steps[i];
      const std::int64_t original = *step.card_raw;
      options_.cancel.acknowledge("restoring " + step.cell);  // a new stop request is answered, not obeyed
      if (read_one(step.cell).value == original) {
        result_.rollback.push_back({step.cell, original, step.card_text, true, true, {}});
        continue;
      }
      result_.rollback.push_back(write_one(step.cell, original));
    }
    result_.cells.clear();
    bool restored = true;
    for (std::size_t i = 0; i < touched; ++i) {
      options_.cancel.acknowledge("reading back the restored " + steps[i].cell);
      result_.cells.push_back(state_of(steps[i], read_one(steps[i].cell)));
      restored = restored && result_.cells.back().status == CellStatus::Original;
    }
    if (!restored)
      result_.outcome = Outcome::Uncertain;
    else
      result_.outcome = result_.interrupted ? Outcome::Interrupted : Outcome::RolledBack;
    if (!restored) result_.reason += "; restoring the old values failed, see the cell states";
    copy_events();
  }

  void reset_amp() {
    try {
      card_.reset();
      result_.reset_done = true;
      result_.reset_needed = false;
    } catch (const std::exception& e) {
      result_.reset_error = std::string("reset failed: ") + e.what();
      result_.outcome = Outcome::Uncertain;
      return;
    }
    // The EEPROM must still hold what was verified (a reset must not have lost it).
    for (const auto& step : result_.plan.steps) {
      if (!step.nv) continue;
      const auto one = read_one(step.cell);
      if (one.value != step.profile_raw) {
        result_.reset_error += (result_.reset_error.empty() ? "after the reset " : ", ") + step.cell +
                               " reads " +
                               (one.value ? text(step.cell, *one.value) : "unknown (" + one.error + ")");
        result_.outcome = Outcome::Uncertain;
      }
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
      if (it == values.end()) return {std::nullopt, "not readable as a fact on this card"};
      return {it->second, {}};
    } catch (const std::exception& e) {
      return {std::nullopt, e.what(), true};
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

  void copy_events() { result_.events = card_.events(); }

  void stop(Outcome outcome, const std::string& reason, Advice advice = Advice::None) {
    result_.outcome = outcome;
    result_.reason = reason;
    result_.reason_advice = advice;
    copy_events();
  }
  void finish(Outcome outcome) { result_.outcome = outcome; }

  const profile::Profile& profile_;
  const params::ParamDb& db_;
  CellAccess& card_;
  const TransactionOptions& options_;
  TransactionResult& result_;
  std::vector<profile::CellWrite> writes_;
  RawValues snapshot_;
  std::set<std::string> asked_;  // every cell read_card() and read_context() asked the card for
  RawValues context_;
};

}  // namespace

const std::vector<std::string>& rule_parameters() {
  static const std::vector<std::string> names{"BRAKEONV",     "BRAKEOFFV",  "BUSOVERV", "BUSUNDERV",
                                              "BUSUNDERVMAX", "MAXCURRENT", "KQP",      "KDP",
                                              "KQI",          "KDI"};
  return names;
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

TransactionResult run_transaction(const profile::Profile& profile, const params::ParamDb& db,
                                  CellAccess& card, const TransactionOptions& options) {
  TransactionResult result;
  Transaction(profile, db, card, options, result).run();
  return result;
}

}  // namespace i20::ops
