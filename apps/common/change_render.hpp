// SPDX-License-Identifier: GPL-2.0-or-later
// Text and JSON for every command that changes a card (set, wpd, faults mask, profile apply,
// fleets): findings, diff and plan tables, the report with its one-line final state, and the
// fleet's result table. Text shows
// engineering units; JSON carries raw counts as well, for scripts.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "errors.hpp"
#include "json.hpp"
#include "ops/apply_run.hpp"
#include "params/param_db.hpp"
#include "profile/diff.hpp"
#include "profile/error.hpp"
#include "profile/finding.hpp"
#include "profile/plan.hpp"

namespace i20::app::render {

using ops::TargetRun;

// Columns padded to their widest cell, two spaces apart, no trailing blanks.
class Table {
 public:
  explicit Table(std::vector<std::string> headers) : rows_{std::move(headers)} {}
  void add(std::vector<std::string> row) { rows_.push_back(std::move(row)); }
  bool empty() const { return rows_.size() == 1; }
  void print(std::ostream& out, const std::string& indent = "  ") const;

 private:
  std::vector<std::vector<std::string>> rows_;
};

// lib's messages with the option that overrides them, where this program has one
// (app::with_advice): a finding's message, a transaction's reason, why a target was not reached.
std::string finding_text(const profile::Finding& finding);
std::string reason_text(const ops::TransactionResult& result);
std::string error_text(const TargetRun& run);

// A cell's state after a change, in words: "written, read back equal" for a verified write
// (the transaction's "intended"), "original (restored)", OTHER or UNKNOWN with why. The
// commands' cell table and the console say the same.
std::string cell_state_text(const ops::CellState& cell);

// "profiles/x.yaml:12: error: NVBRAKEOFFV: must be below BRAKEONV ... [brake-order]";
// findings without a line name `file`.
void print_findings(std::ostream& out, const std::vector<profile::Finding>& findings,
                    const std::string& file);
void print_load_error(std::ostream& out, const profile::ProfileError& error, const std::string& file);
// "1 error, 2 warnings" / "no findings".
std::string findings_summary(const std::vector<profile::Finding>& findings);
app::Json findings_json(const std::vector<profile::Finding>& findings);
app::Json load_error_json(const profile::ProfileError& error);

void print_diff(std::ostream& out, const std::vector<profile::DiffRow>& rows);
app::Json diff_json(const std::vector<profile::DiffRow>& rows);

void print_plan(std::ostream& out, const profile::Plan& plan);
app::Json plan_json(const profile::Plan& plan);

// The whole report of one apply: plan, writes, the final state in one line, the card
// state table when a rollback happened, the backup and the reset advice. `source` names
// the profile file in findings that are not about one entry.
// `plan_shown`: the plan was printed already, as the transaction made it.
void print_run(std::ostream& out, const TargetRun& run, const params::ParamDb& db, const std::string& source,
               bool plan_shown = false);
// "APPLIED AND VERIFIED: 5 values written, reset needed", "ROLLBACK FAILED: card state below", ...
std::string outcome_line(const TargetRun& run);
// The one line for stderr when a change did not end well: the first broken rule for a
// refusal, the outcome line otherwise.
std::string error_line(const TargetRun& run);
// "applied-and-verified", ..., or "not-reached".
std::string outcome_name(const TargetRun& run);
app::Json run_json(const TargetRun& run);

// What the fleet was asked for, so its table shows it.
struct FleetRequest {
  bool reset = false;    // --reset: a RESET column (done, not needed, pending, would reset, failed, not sent)
  bool dry_run = false;  // --dry-run: what each target would write, instead of what it wrote
};

// One row per target, then the details of every target that did not end well. A dry run's
// table names the cells each target would write and ends "DRY RUN: would write N cells".
void print_fleet(std::ostream& out, const std::vector<TargetRun>& runs, const params::ParamDb& db,
                 const std::string& source, const FleetRequest& request = {});
// The RESET column's state of one target.
std::string reset_state(const TargetRun& run);

}  // namespace i20::app::render
