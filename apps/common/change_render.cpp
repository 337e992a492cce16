// SPDX-License-Identifier: GPL-2.0-or-later
#include "change_render.hpp"

#include <algorithm>
#include <cstdio>
#include <ostream>

#include "params/value.hpp"

namespace i20::app::render {

std::string cell_state_text(const ops::CellState& cell) {
  switch (cell.status) {
    case ops::CellStatus::Intended: return "written, read back equal";
    case ops::CellStatus::Original: return "original (restored)";
    case ops::CellStatus::Other: return "OTHER: neither the old nor the new value";
    case ops::CellStatus::Unknown: return "UNKNOWN: " + cell.error;
  }
  return "UNKNOWN";
}

namespace {

using ops::CellStatus;
using ops::Outcome;
using ops::TargetRun;

std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

app::Json nullable(const std::optional<std::int64_t>& value) {
  return value ? app::Json(*value) : app::Json();
}

app::Json strings_json(const std::vector<std::string>& items) {
  auto arr = app::Json::array();
  for (const auto& s : items) arr.push(s);
  return arr;
}

app::Json writes_json(const std::vector<ops::WriteRecord>& records) {
  auto arr = app::Json::array();
  for (const auto& w : records) {
    auto j = app::Json::object();
    j.set("cell", w.cell).set("raw", w.value).set("text", w.value_text).set("ok", w.ok);
    j.set("skipped", w.skipped).set("error", w.error);
    arr.push(std::move(j));
  }
  return arr;
}

app::Json cells_json(const std::vector<ops::CellState>& cells) {
  auto arr = app::Json::array();
  for (const auto& c : cells) {
    auto j = app::Json::object();
    j.set("cell", c.cell).set("original", c.original).set("intended", c.intended);
    j.set("actual", nullable(c.actual)).set("actual_text", c.actual_text);
    j.set("status", ops::to_string(c.status)).set("error", c.error);
    arr.push(std::move(j));
  }
  return arr;
}

std::string text_of(const params::ParamDb& db, const std::string& cell, std::int64_t raw) {
  const params::Param* p = db.find(cell);
  return p ? params::format_engineering(*p, raw) : std::to_string(raw);
}

// What stopped the apply, for the rollback line: the write that failed, else the verify.
std::string failure_of(const TargetRun& run) {
  const auto& r = *run.result;
  if (r.interrupted) return "a stop request (Ctrl-C, SIGTERM or SIGHUP)";
  for (const auto& w : r.writes)
    if (!w.ok) return w.cell + " failed";
  return "the read-back verify failed";
}

std::string reset_line(const TargetRun& run) {
  const auto& r = *run.result;
  if (r.reset_done) return r.reset_error.empty() ? " and the card was reset: they are live now" : "";
  if (r.reset_needed || !run.not_live.empty()) return ", reset needed";
  return "";
}

void print_writes(std::ostream& out, const std::string& title, const std::vector<ops::WriteRecord>& records) {
  if (records.empty()) return;
  out << title << "\n";
  Table t({"CELL", "VALUE", "RESULT"});
  for (const auto& w : records)
    t.add({w.cell, w.value_text,
           w.skipped ? "skipped: it still held this value"
           : w.ok    ? "written, read back equal"
                     : "FAILED: " + w.error});
  t.print(out);
}

void print_cells(std::ostream& out, const TargetRun& run, const params::ParamDb& db) {
  Table t({"CELL", "BEFORE", "INTENDED", "NOW", "STATE"});
  for (const auto& c : run.result->cells) {
    t.add({c.cell, text_of(db, c.cell, c.original), text_of(db, c.cell, c.intended), c.actual_text,
           cell_state_text(c)});
  }
  t.print(out);
}

void print_reset_advice(std::ostream& out, const TargetRun& run) {
  const auto& r = *run.result;
  const bool applied = r.outcome == Outcome::Done || r.outcome == Outcome::NothingToDo;
  if (!r.reset_error.empty())
    out << "RESET PROBLEM: " << r.reset_error
        << ". The EEPROM values were written and verified before it; check the card's logic power, then "
        << "`i20 " << run.target.flags() << " reset`.\n";
  if (applied && !r.reset_done && (r.reset_needed || !run.not_live.empty())) {
    out << "Reset needed: the EEPROM values take effect at the next reset of the 8I20";
    if (!run.not_live.empty()) out << " (not live yet: " << run.not_live.size() << " of them)";
    // apply --reset resets only after it wrote something: with nothing to do, only `reset` helps.
    out << ": run `i20 " << run.target.flags() << " reset`.\n";
  }
  if (!run.card_reset.empty())
    out << "WARNING: " << run.card_reset << "; "
        << (r.outcome == Outcome::Done ? "the EEPROM holds the verified values: reset the card again"
                                       : "reset the card once its EEPROM is as you want it")
        << " (`i20 " << run.target.flags() << " reset`) so the working values match the EEPROM.\n";
}

// After a failed rollback, what the cell table means and how to get back to a known state.
void print_rollback_failed(std::ostream& out, const TargetRun& run) {
  const auto& r = *run.result;
  const auto has = [&](CellStatus status) {
    return std::ranges::any_of(r.cells, [status](const auto& c) { return c.status == status; });
  };
  if (has(CellStatus::Intended) && has(CellStatus::Original))
    out << "The card holds a MIX of old and new values. ";
  if (has(CellStatus::Unknown))
    out << "Cells marked UNKNOWN could not be read: they may hold the old value, the new one or neither (a "
           "write cut short). ";
  out << "When the card answers again, ";
  if (!r.backup.empty())
    out << "restore the previous values with `i20 " << run.target.flags() << " profile apply "
        << r.backup.string() << "`, or apply the profile again.\n";
  else
    out << "apply the profile again.\n";
}

void print_next_steps(std::ostream& out, const TargetRun& run) {
  const auto& r = *run.result;
  if (r.outcome == Outcome::RolledBack)
    out << "Every value written was restored and read back. Fix the cause and try again.\n";
  if (r.outcome == Outcome::Interrupted && !r.writes.empty())
    out << "Stopped on request (the line above names the signal): every value written was restored and read "
           "back.\n";
  if (r.outcome == Outcome::Uncertain && !r.rollback.empty()) print_rollback_failed(out, run);
  if (!run.mode_left_on.empty() && outcome_line(run).find(run.mode_left_on) == std::string::npos)
    out << "WARNING: " << run.mode_left_on << "\n";
  if (run.retries > 0)
    out << "note: " << plural(run.retries, "read or write was", "reads or writes were")
        << " repeated after lost or garbled replies\n";
}

}  // namespace

void Table::print(std::ostream& out, const std::string& indent) const {
  std::vector<std::size_t> width;
  for (const auto& row : rows_) {
    width.resize(std::max(width.size(), row.size()), 0);
    for (std::size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], row[i].size());
  }
  for (const auto& row : rows_) {
    std::string line = indent;
    for (std::size_t i = 0; i < row.size(); ++i) {
      line += row[i];
      if (i + 1 < row.size()) line += std::string(width[i] - row[i].size() + 2, ' ');
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << "\n";
  }
}

std::string finding_text(const profile::Finding& finding) {
  return with_advice(finding.message, finding.advice);
}

std::string reason_text(const ops::TransactionResult& result) {
  return with_advice(result.reason, result.reason_advice);
}

std::string error_text(const TargetRun& run) {
  return with_advice(run.error, run.error_advice);
}

void print_findings(std::ostream& out, const std::vector<profile::Finding>& findings,
                    const std::string& file) {
  for (const auto& f : findings)
    out << (f.where.empty() ? file : f.where) << ": " << profile::to_string(f.severity) << ": " << f.key
        << ": " << finding_text(f) << " [" << f.rule << "]\n";
}

void print_load_error(std::ostream& out, const profile::ProfileError& e, const std::string& file) {
  out << (e.where().empty() ? file : e.where()) << ": error: " << (e.key().empty() ? "" : e.key() + ": ")
      << e.reason() << " [" << e.rule() << "]\n";
}

std::string findings_summary(const std::vector<profile::Finding>& findings) {
  const auto errors = static_cast<std::size_t>(std::ranges::count_if(
      findings, [](const profile::Finding& f) { return f.severity == profile::Severity::Error; }));
  const auto warnings = findings.size() - errors;
  if (findings.empty()) return "no findings";
  return plural(errors, "error", "errors") + ", " + plural(warnings, "warning", "warnings");
}

app::Json findings_json(const std::vector<profile::Finding>& findings) {
  auto arr = app::Json::array();
  for (const auto& f : findings) {
    auto j = app::Json::object();
    j.set("severity", profile::to_string(f.severity)).set("key", f.key).set("rule", f.rule);
    j.set("message", finding_text(f)).set("where", f.where);
    arr.push(std::move(j));
  }
  return arr;
}

app::Json load_error_json(const profile::ProfileError& e) {
  auto arr = app::Json::array();
  auto j = app::Json::object();
  j.set("severity", "error").set("key", e.key()).set("rule", e.rule()).set("message", e.reason());
  j.set("where", e.where());
  arr.push(std::move(j));
  return arr;
}

void print_diff(std::ostream& out, const std::vector<profile::DiffRow>& rows) {
  Table t({"CELL", "PROFILE", "CARD", "", "FROM"});
  for (const auto& r : rows)
    t.add({r.cell, r.profile_text, r.card_text, r.equal ? "same" : "DIFFERS", r.where});
  t.print(out);
}

app::Json diff_json(const std::vector<profile::DiffRow>& rows) {
  auto arr = app::Json::array();
  for (const auto& r : rows) {
    auto j = app::Json::object();
    j.set("cell", r.cell).set("nv", r.nv).set("where", r.where);
    j.set("profile_raw", r.profile_raw).set("profile_text", r.profile_text);
    j.set("card_raw", nullable(r.card_raw)).set("card_text", r.card_text).set("equal", r.equal);
    arr.push(std::move(j));
  }
  return arr;
}

void print_plan(std::ostream& out, const profile::Plan& plan) {
  if (!plan.empty()) {
    out << "Plan: " << plural(plan.steps.size(), "write", "writes")
        << " in this order (EEPROM first; thresholds and gains in a safe order):\n";
    Table t({"#", "CELL", "NOW", "NEW", "FROM"});
    for (std::size_t i = 0; i < plan.steps.size(); ++i) {
      const auto& s = plan.steps[i];
      t.add({std::to_string(i + 1), s.cell, s.card_text, s.profile_text, s.where});
    }
    t.print(out);
  }
  if (plan.unchanged.empty()) return;
  out << "Already set (not written): ";
  for (std::size_t i = 0; i < plan.unchanged.size(); ++i)
    out << (i ? ", " : "") << plan.unchanged[i].cell << " " << plan.unchanged[i].profile_text;
  out << "\n";
}

app::Json plan_json(const profile::Plan& plan) {
  auto j = app::Json::object();
  j.set("steps", diff_json(plan.steps)).set("unchanged", diff_json(plan.unchanged));
  j.set("reset_needed", plan.reset_needed);
  return j;
}

std::string outcome_name(const TargetRun& run) {
  return ops::to_string(run.outcome);
}

std::string outcome_line(const TargetRun& run) {
  if (!run.result) {
    const bool refused = run.outcome == Outcome::Refused || run.outcome == Outcome::BadInput;
    return std::string(refused                               ? "REFUSED: "
                       : run.outcome == Outcome::Interrupted ? "INTERRUPTED: "
                                                             : "NOT REACHED: ") +
           error_text(run) + "; nothing was written";
  }
  const auto& r = *run.result;
  const std::size_t steps = r.plan.steps.size();
  const std::size_t total = steps + r.plan.unchanged.size();
  const bool says = r.reason.find("nothing was written") != std::string::npos;
  const std::string nothing = says ? "" : "; nothing was written";
  switch (run.outcome) {
    case Outcome::Done:
      return "APPLIED AND VERIFIED: " + plural(steps, "value", "values") + " written" + reset_line(run);
    case Outcome::NothingToDo:
      return "NOTHING TO DO: the card already holds " +
             (total == 1 ? std::string("the value") : "all " + plural(total, "value", "values")) +
             "; nothing was written" + reset_line(run);
    case Outcome::DryRun:
      return "DRY RUN: " + plural(steps, "value", "values") + " would be written, " +
             std::to_string(total - steps) + " already set; nothing was written";
    case Outcome::RolledBack:
      return "ROLLED BACK AND VERIFIED after " + failure_of(run) + ": the card holds its previous values";
    case Outcome::Interrupted:
      return r.writes.empty() ? "INTERRUPTED: " + reason_text(r) + nothing
                              : "INTERRUPTED AND ROLLED BACK: every value written was restored and read back";
    case Outcome::Uncertain:
      if (!r.reset_error.empty()) return "APPLIED AND VERIFIED, BUT THE RESET FAILED: " + r.reset_error;
      return r.rollback.empty() ? "CARD STATE UNCERTAIN: " + reason_text(r)
                                : "ROLLBACK FAILED after " + failure_of(run) + ": card state below";
    case Outcome::Refused:
    case Outcome::BadInput:
      if (profile::has_errors(r.findings))
        return "REFUSED by the rule" + std::string(r.findings.size() > 1 ? "s" : "") +
               " above; nothing was written";
      // Exit 3 is a refusal; exit 2 is input that could not be used, and says so.
      return std::string(r.outcome == Outcome::Refused ? "REFUSED: " : "BAD INPUT: ") + reason_text(r) +
             nothing;
    case Outcome::Failed:
    case Outcome::OutputLost: return "NOT DONE: " + reason_text(r) + nothing;
    case Outcome::FaultsRemain: break;
  }
  return reason_text(r);
}

std::string error_line(const TargetRun& run) {
  const bool refused = run.outcome == Outcome::Refused || run.outcome == Outcome::BadInput;
  if (refused && run.result) return "refused: " + reason_text(*run.result);
  // The cell table goes to stdout; a mode left on must be on the one line too.
  std::string line = outcome_line(run);
  if (!run.mode_left_on.empty() && line.find(run.mode_left_on) == std::string::npos)
    line += "; and " + run.mode_left_on;
  return line;
}

void print_run(std::ostream& out, const TargetRun& run, const params::ParamDb& db, const std::string& source,
               bool plan_shown) {
  if (!run.result) {
    out << outcome_line(run) << "\n";
    return;
  }
  const auto& r = *run.result;
  out << "Card: " << r.card << "\n";
  print_findings(out, r.findings, source);
  const bool refused = run.outcome == Outcome::Refused || run.outcome == Outcome::BadInput;
  if (!plan_shown && !refused) print_plan(out, r.plan);
  const bool rolled = !r.rollback.empty() || (r.outcome == Outcome::Uncertain && !r.cells.empty());
  if (rolled) {
    print_writes(out, "Writes:", r.writes);
    print_writes(out, "Restoring the previous values:", r.rollback);
  }
  out << outcome_line(run) << "\n";
  if (rolled) {
    out << "  why: " << reason_text(r) << "\n";
    print_cells(out, run, db);
  }
  for (const auto& event : r.events) out << "NOTE: " << event << "\n";
  if (!r.backup.empty()) out << "Backup of the previous values: " << r.backup.string() << "\n";
  print_reset_advice(out, run);
  print_next_steps(out, run);
}

app::Json run_json(const TargetRun& run) {
  auto j = app::Json::object();
  j.set("target", run.target.text).set("outcome", outcome_name(run)).set("ok", run.ok());
  j.set("exit_code", run.exit_code()).set("summary", outcome_line(run)).set("error", error_text(run));
  if (run.result) {
    const auto& r = *run.result;
    j.set("card", r.card).set("reason", reason_text(r)).set("findings", findings_json(r.findings));
    j.set("plan", plan_json(r.plan))
        .set("backup", r.backup.empty() ? app::Json() : app::Json(r.backup.string()));
    j.set("writes", writes_json(r.writes)).set("rollback", writes_json(r.rollback));
    j.set("cells", cells_json(r.cells)).set("reset_needed", r.reset_needed || !run.not_live.empty());
    j.set("reset_done", r.reset_done).set("reset_error", r.reset_error);
    j.set("events", strings_json(r.events)).set("interrupted", r.interrupted);
  }
  j.set("not_live", strings_json(run.not_live)).set("card_reset", run.card_reset);
  j.set("refused_by_card", run.refused_by_card);
  j.set("retries", run.retries).set("seconds", run.seconds);
  return j;
}

std::string reset_state(const TargetRun& run) {
  if (!run.result) return "not sent";
  const auto& r = *run.result;
  if (!r.reset_error.empty()) return "FAILED";
  if (r.reset_done) return "done";
  if (run.outcome == Outcome::DryRun) return r.plan.reset_needed ? "would reset" : "only if one is pending";
  if (run.outcome != Outcome::Done && run.outcome != Outcome::NothingToDo) return "not sent";
  return r.reset_needed || !run.not_live.empty() ? "PENDING" : "not needed";
}

namespace {

std::string cell_names(const profile::Plan& plan) {
  std::string names;
  for (const auto& step : plan.steps) names += (names.empty() ? "" : ", ") + step.cell;
  return names;
}

// One row: what the target wrote (or would write, on a dry run), and why not.
std::vector<std::string> fleet_row(const TargetRun& run, const FleetRequest& request) {
  const auto* r = run.result ? &*run.result : nullptr;
  std::vector<std::string> row{run.target.text, outcome_name(run)};
  if (request.dry_run) {
    const bool planned = r && run.outcome == Outcome::DryRun;
    row.push_back(planned ? std::to_string(r->plan.steps.size()) : "-");
    if (request.reset) row.push_back(reset_state(run));
    row.push_back(!r ? error_text(run) : planned ? cell_names(r->plan) : reason_text(*r));
    return row;
  }
  row.push_back(r ? std::to_string(std::ranges::count_if(r->writes, [](const auto& w) { return w.ok; }))
                  : "-");
  if (request.reset) row.push_back(reset_state(run));
  std::string note = !r ? error_text(run) : !r->backup.empty() ? r->backup.string() : reason_text(*r);
  if (r && run.ok() && !request.reset && (r->reset_needed || !run.not_live.empty()))
    note += " (reset needed)";
  if (r && !run.ok() && !r->backup.empty()) note = reason_text(*r) + "; backup " + r->backup.string();
  row.push_back(note);
  return row;
}

std::string fleet_summary(const std::vector<TargetRun>& runs, const FleetRequest& request) {
  const auto ok = static_cast<std::size_t>(std::ranges::count_if(runs, [](const auto& r) { return r.ok(); }));
  if (!request.dry_run)
    return std::to_string(ok) + " of " + plural(runs.size(), "target", "targets") +
           " applied and verified (or had nothing to do); " + std::to_string(runs.size() - ok) + " did not";
  std::size_t cells = 0;
  for (const auto& run : runs)
    if (run.result && run.outcome == Outcome::DryRun) cells += run.result->plan.steps.size();
  std::string line = "DRY RUN: would write " + plural(cells, "cell", "cells") + " on " + std::to_string(ok) +
                     " of " + plural(runs.size(), "target", "targets") + "; nothing was written";
  if (ok < runs.size()) line += "; " + std::to_string(runs.size() - ok) + " would not be applied (below)";
  return line;
}

}  // namespace

void print_fleet(std::ostream& out, const std::vector<TargetRun>& runs, const params::ParamDb& db,
                 const std::string& source, const FleetRequest& request) {
  std::vector<std::string> headers{"TARGET", "OUTCOME", request.dry_run ? "WOULD WRITE" : "WRITES"};
  if (request.reset) headers.push_back("RESET");
  headers.push_back(request.dry_run ? "CELLS / REASON" : "BACKUP / REASON");
  Table t(headers);
  for (const auto& run : runs) t.add(fleet_row(run, request));
  t.print(out, "");
  for (const auto& run : runs) {
    // Not reached: the table's reason is the whole story.
    if (!run.result || (run.ok() && run.card_reset.empty())) continue;
    out << "\n== " << run.target.text << "\n";
    print_run(out, run, db, source);
  }
  out << "\n" << fleet_summary(runs, request) << "\n";
}

}  // namespace i20::app::render
