// SPDX-License-Identifier: GPL-2.0-or-later
// i20 profile validate | diff | apply | save  (and `i20 tune`, cmd_tune.cpp)
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "change_render.hpp"
#include "cmd_profile_export.hpp"
#include "cmd_tune.hpp"
#include "context.hpp"
#include "fleet_progress.hpp"
#include "lbp/bytes.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/core/read.hpp"
#include "ops/core/signals.hpp"
#include "ops/fleet.hpp"
#include "ops/profile_apply.hpp"
#include "ops/profile_diff.hpp"
#include "ops/undo.hpp"
#include "output_file.hpp"
#include "profile/backup.hpp"
#include "profile/diff.hpp"
#include "profile/loader.hpp"
#include "profile/save.hpp"
#include "profile/validate.hpp"
#include "profile/writer.hpp"
#include "profile_lookup.hpp"

namespace i20::cli {
namespace {

using profile::Profile;

namespace render = app::render;

// A card named by --target, the global flags or COMPORT (as every i20 command reads it).
bool has_card(Context& ctx, const std::vector<std::string>& targets) {
  return !targets.empty() || ctx.session().endpoint_if_any().has_value();
}

// The targets a command names: --target (repeatable) or the global --port/--sim/--eth.
// `--sim-control` only reaches simulators: with no simulator among them it is an error, not
// silently ignored.
std::vector<ops::Endpoint> targets_of(Context& ctx, const std::vector<std::string>& targets) {
  auto endpoints = ctx.session().targets(targets);
  const bool any_sim =
      std::ranges::any_of(endpoints, [](const auto& e) { return e.kind == ops::Endpoint::Kind::Sim; });
  if (!ctx.options.link.sim_control.empty() && !any_sim)
    throw UsageError("--sim-control reaches only simulators (--sim, sim targets), and " +
                     endpoints.front().text + " is not one");
  return endpoints;
}

// The one card save reads (read-only: Ctrl-C may stop it anywhere).
std::unique_ptr<ops::Amp> open_amp(Context& ctx, const std::vector<std::string>& targets,
                                   const params::ParamDb& db) {
  const auto endpoints = targets_of(ctx, targets);
  if (endpoints.size() != 1) throw UsageError("this command reads one card: give a single --target");
  return ctx.session().open(endpoints.front(), db);
}

struct Loaded {
  std::optional<Profile> profile;
  std::optional<profile::ProfileError> error;
};

Loaded try_load(const params::ParamDb& db, const std::string& file) {
  try {
    return {profile::load_profile_file(file, db), std::nullopt};
  } catch (const profile::ProfileError& e) {
    return {std::nullopt, e};
  }
}

// Reports a profile that cannot be read (file:line: key: reason [rule]) and sets exit code 2.
void report_invalid(Context& ctx, const std::string& file, const profile::ProfileError& e) {
  ctx.record(ops::Outcome::BadInput);
  if (!ctx.options.json) return render::print_load_error(std::cerr, e, file);
  auto j = app::Json::object();
  j.set("file", file)
      .set("valid", false)
      .set("outcome", "invalid")
      .set("exit_code", ops::exit_code(ops::Outcome::BadInput));
  ctx.print_json(j.set("findings", render::load_error_json(e)));
}

// Loads FILE, or reports why not. Nothing is sent to a card before this succeeds.
std::optional<Profile> load(Context& ctx, const params::ParamDb& db, const std::string& file) {
  auto loaded = try_load(db, file);
  if (loaded.error) report_invalid(ctx, file, *loaded.error);
  return loaded.profile;
}

// The apply that `validate` and `apply --dry-run` predict, and `apply` and `undo` run:
// one request for every command, so a prediction uses exactly the rules of the real thing.
ops::ApplyRequest apply_request(Context& ctx, const Profile& profile, const params::ParamDb& db, bool force,
                                bool allow_unverified) {
  return {.profile = &profile,
          .db = &db,
          .force = force,
          .allow_unverified = allow_unverified,
          .cancel = ctx.session().cancel(),
          .open = ctx.session().open_options()};
}

// ------------------------------------------------------------------ validate
struct ValidateOptions {
  std::vector<std::string> files;
  std::vector<std::string> targets;
  bool force = false;
  bool allow_unverified = false;
};

// What validate cannot judge without a card (the rules compare with what it measures).
constexpr const char* kNeedsCard =
    "the measured-bus rules (bus-measured-*: each threshold against the bus voltage the card measures now) "
    "need a card and were not judged; values the profile does not set were judged by their database "
    "defaults. Give --target, --port or --sim to judge the profile as apply does";

// One file without a card: findings printed as they are found (text), its entry returned (JSON).
app::Json validate_offline(Context& ctx, const params::ParamDb& db, const std::string& file, bool force,
                           ops::Outcome& outcome) {
  auto j = app::Json::object();
  j.set("file", file);
  const auto loaded = try_load(db, file);
  if (!loaded.profile) {
    outcome = ops::Outcome::BadInput;
    if (!ctx.options.json) {
      render::print_load_error(std::cout, *loaded.error, file);
      std::cout << file << ": INVALID (cannot be loaded)\n";
    }
    return j.set("valid", false).set("findings", render::load_error_json(*loaded.error));
  }
  const auto findings = profile::validate(*loaded.profile, db, {nullptr, force, std::nullopt});
  const bool valid = !profile::has_errors(findings);
  outcome = valid ? ops::Outcome::DryRun : ops::Outcome::Refused;  // apply would refuse it (exit 3)
  if (!ctx.options.json) {
    render::print_findings(std::cout, findings, file);
    std::cout << file << ": " << (valid ? "valid" : "INVALID") << " (" << render::findings_summary(findings)
              << "), without a card\n";
  }
  return j.set("valid", valid).set("findings", render::findings_json(findings));
}

// The transaction's reason without its "; nothing was written" (validate never writes).
std::string why_refused(std::string reason) {
  const std::string tail = "; nothing was written";
  if (reason.ends_with(tail)) reason.erase(reason.size() - tail.size());
  return reason;
}

// "valid (no findings, checked against CARD)" or why apply would not go ahead.
std::string verdict(const ops::TargetRun& run) {
  const std::string card = run.result ? ", checked against " + run.result->card : std::string();
  if (!run.result)
    return "NOT CHECKED (" + run.target.text + " not reached: " + render::error_text(run) + ")";
  const auto& r = *run.result;
  if (run.outcome == ops::Outcome::DryRun)
    return "valid (" + render::findings_summary(r.findings) + card + ")";
  if (run.outcome == ops::Outcome::Failed)
    return "NOT CHECKED (" + render::findings_summary(r.findings) + card + "): " + render::reason_text(r);
  return "INVALID (" + render::findings_summary(r.findings) + card +
         "): apply would be refused: " + app::with_advice(why_refused(r.reason), r.reason_advice);
}

app::Json validation_json(const ops::TargetRun& run) {
  auto j = app::Json::object();
  j.set("target", run.target.text).set("valid", run.outcome == ops::Outcome::DryRun);
  j.set("outcome", run.outcome == ops::Outcome::DryRun ? "valid" : ops::to_string(run.outcome));
  j.set("exit_code", run.exit_code()).set("card", run.result ? app::Json(run.result->card) : app::Json());
  j.set("reason", run.result ? render::reason_text(*run.result) : render::error_text(run));
  return j.set("findings", run.result ? render::findings_json(run.result->findings) : app::Json::array());
}

// Refused by the rules that need no card (range, guard, read-only, the card's limits), as
// apply refuses before it opens a link: the findings, and the refusal's one line.
app::Json refused_offline(Context& ctx, const Profile& profile, const params::ParamDb& db,
                          const std::string& file, bool force, const Error& e) {
  const auto findings = profile::validate_values(profile, db, force);
  if (!ctx.options.json) {
    render::print_findings(std::cout, findings, file);
    std::cout << file << ": INVALID (" << render::findings_summary(findings)
              << "): apply would be refused before the card is asked: "
              << app::with_advice(e.what(), e.advice()) << "\n";
  }
  auto j = app::Json::object();
  j.set("file", file)
      .set("valid", false)
      .set("outcome", "refused")
      .set("reason", app::with_advice(e.what(), e.advice()));
  return j.set("findings", render::findings_json(findings));
}

// One file against the cards: the transaction's dry run on each (read, validate with the
// measured bus, order, the device layer's rules), exactly what apply runs before it writes.
app::Json validate_on_cards(Context& ctx, const params::ParamDb& db,
                            const std::vector<ops::Endpoint>& targets, const std::string& file,
                            const ValidateOptions& o, ops::Outcome& outcome) {
  const auto loaded = try_load(db, file);
  if (!loaded.profile) return validate_offline(ctx, db, file, o.force, outcome);  // reports the load error
  auto request = apply_request(ctx, *loaded.profile, db, o.force, o.allow_unverified);
  request.dry_run = true;
  std::optional<ops::ProfileApply> apply;
  try {
    apply.emplace(request);
  } catch (const Error& e) {
    outcome = ops::outcome_of(e.kind());
    return refused_offline(ctx, *loaded.profile, db, file, o.force, e);
  }
  const auto runs = apply->run_on(targets);
  outcome = ops::fleet_outcome(runs);
  auto j = app::Json::object();
  j.set("file", file).set("valid", outcome == ops::Outcome::DryRun);
  if (targets.size() == 1) {  // the one card's verdict on the file's own entry, as without a card
    const auto& run = runs.front();
    j.set("outcome", run.outcome == ops::Outcome::DryRun ? "valid" : ops::to_string(run.outcome));
    j.set("reason", run.result ? render::reason_text(*run.result) : render::error_text(run));
    j.set("findings", run.result ? render::findings_json(run.result->findings) : app::Json::array());
  }
  auto per_target = app::Json::array();
  for (const auto& run : runs) {
    per_target.push(validation_json(run));
    if (ctx.options.json) continue;
    if (targets.size() > 1) std::cout << "== " << run.target.text << "\n";
    if (run.result) render::print_findings(std::cout, run.result->findings, file);
    std::cout << file << ": " << verdict(run) << "\n";
  }
  return j.set("targets", per_target);
}

void run_validate(Context& ctx, const ValidateOptions& o) {
  const auto& db = ctx.session().db();
  std::vector<ops::Endpoint> targets;
  if (has_card(ctx, o.targets)) targets = targets_of(ctx, o.targets);
  auto files = app::Json::array();
  ops::Outcome worst = ops::Outcome::DryRun;
  for (const auto& file : o.files) {
    ops::Outcome outcome = ops::Outcome::DryRun;
    files.push(targets.empty() ? validate_offline(ctx, db, file, o.force, outcome)
                               : validate_on_cards(ctx, db, targets, file, o, outcome));
    worst = ops::most_serious(worst, outcome);
  }
  ctx.record(worst);
  if (!ctx.options.json) {
    if (targets.empty()) std::cout << "note: " << kNeedsCard << "\n";
    return;
  }
  auto j = app::Json::object();
  j.set("valid", worst == ops::Outcome::DryRun).set("exit_code", ctx.exit_code());
  j.set("card", targets.size() == 1 ? app::Json(targets.front().text) : app::Json());
  if (targets.empty()) j.set("not_judged", kNeedsCard);
  ctx.print_json(j.set("files", files));
}

// ------------------------------------------------------------------ diff
struct DiffOptions {
  std::string file;
  std::vector<std::string> targets;
};

// The comparison and its answer are lib/ops's (ops::ProfileDiff); this adds what is printed.
struct TargetDiff : ops::ProfileDiff {
  ops::Endpoint target;
  std::string card;   // describe(), when reached
  std::string flags;  // the target's flags, for the advice
};

TargetDiff diff_one(const Profile& profile, const std::vector<std::string>& names,
                    const ops::Endpoint& target, const ops::AmpOpener& open) {
  TargetDiff d;
  d.target = target;
  try {
    const auto amp = open();
    d.card = amp->describe();
    d.flags = amp->endpoint().flags();
    profile::RawValues values;
    for (const auto& r : ops::read_values(*amp, names))
      if (r.fact()) values[r.param->name] = *r.raw;
    d.rows = profile::diff(profile, amp->db(), values);
  } catch (const Error& e) {
    d.error = app::with_advice(e.what(), e.advice());
    d.interrupted = e.kind() == ErrorKind::Cancelled;
  } catch (const std::exception& e) {
    d.error = e.what();
  }
  return d;
}

void print_diff_summary(const TargetDiff& d, const std::string& file) {
  const auto differ = d.differ();
  const auto nv = std::ranges::count_if(d.rows, [](const auto& r) { return !r.equal && r.card_raw && r.nv; });
  if (d.unknown() > 0)
    std::cout << d.unknown() << " of " << d.rows.size()
              << " values cannot be read as facts on this card (address not confirmed for its firmware): "
                 "not compared; `i20 "
              << d.flags << " discover` confirms them\n";
  if (differ == 0 && d.unknown() == 0) {
    std::cout << "The card holds every value of the profile: applying it would write nothing.\n";
    return;
  }
  if (differ == 0) return;
  std::cout << differ << " of " << d.rows.size() << " values differ"
            << (nv ? " (" + std::to_string(nv) + " in the EEPROM: they take effect after a reset)" : "")
            << "; `i20 " << d.flags << " profile apply " << file << "` writes only those.\n";
}

app::Json diff_entry_json(const TargetDiff& d) {
  auto j = app::Json::object();
  j.set("target", d.target.text).set("card", d.card.empty() ? app::Json() : app::Json(d.card));
  j.set("differ", d.differ())
      .set("unknown", d.unknown())
      .set("exit_code", ops::exit_code(d.comparison()))
      .set("error", d.error);
  return j.set("rows", render::diff_json(d.rows));
}

void print_diff_text(const Profile& profile, const std::string& file, const std::vector<TargetDiff>& diffs) {
  for (const auto& d : diffs) {
    if (diffs.size() > 1) std::cout << "== " << d.target.text << "\n";
    if (!d.error.empty()) {
      std::cout << d.target.text << ": NOT READ: " << d.error << "\n";
      continue;
    }
    std::cout << profile.name << " (" << file << ") against " << d.card << ":\n";
    render::print_diff(std::cout, d.rows);
    print_diff_summary(d, file);
  }
  if (diffs.size() < 2) return;
  const auto count = [&](ops::Comparison c) {
    return std::ranges::count_if(diffs, [c](const auto& d) { return d.comparison() == c; });
  };
  std::cout << "\n"
            << count(ops::Comparison::Same) << " of " << diffs.size() << " targets hold every value; "
            << count(ops::Comparison::Differs) << " differ; "
            << diffs.size() - count(ops::Comparison::Same) - count(ops::Comparison::Differs)
            << " could not be compared\n";
}

void run_diff(Context& ctx, const DiffOptions& o) {
  const auto& db = ctx.session().db();
  const auto profile = load(ctx, db, o.file);
  if (!profile) return;
  std::vector<std::string> names;
  try {
    for (const auto& w : profile::cell_writes(*profile, db)) names.push_back(w.cell);
  } catch (const profile::ProfileError& e) {  // a cell set twice, a target that cannot be met
    return report_invalid(ctx, o.file, e);
  }
  const auto targets = targets_of(ctx, o.targets);
  std::vector<TargetDiff> diffs(targets.size());
  ops::for_each_target(targets, db, ctx.session().open_options(), ctx.session().cancel(),
                       [&](std::size_t i, const ops::AmpOpener& opener) {
                         diffs[i] = diff_one(*profile, names, targets[i], opener);
                       });
  auto comparison = ops::Comparison::Same;
  for (const auto& d : diffs) comparison = ops::most_serious(comparison, d.comparison());
  ctx.record(comparison);
  if (!ctx.options.json) {
    print_diff_text(*profile, o.file, diffs);
    for (const auto& d : diffs)
      if (!d.error.empty()) std::cerr << "i20: error: " << d.target.text << ": " << d.error << "\n";
    return;
  }
  auto j = targets.size() == 1 ? diff_entry_json(diffs.front()) : app::Json::object();
  j.set("file", o.file).set("profile", profile->name).set("exit_code", ops::exit_code(comparison));
  if (targets.size() > 1) {
    auto arr = app::Json::array();
    for (const auto& d : diffs) arr.push(diff_entry_json(d));
    j.set("targets", std::move(arr));
  }
  ctx.print_json(j);
}

// ------------------------------------------------------------------ apply
struct ApplyCliOptions {
  std::string file;
  std::vector<std::string> targets;
  std::string to;          // retarget: nv | working | both
  std::string backup_dir;  // empty: $XDG_STATE_HOME/i20/backups
  bool dry_run = false;
  bool force = false;
  bool allow_unverified = false;
  bool reset = false;
  bool yes = false;
};

std::string names_of(const std::vector<ops::Endpoint>& targets) {
  std::string text;
  for (const auto& t : targets) text += (text.empty() ? "" : ", ") + t.text;
  return text;
}

// A reset makes the new EEPROM values live at once: asked before anything is sent.
void require_reset_confirmed(Context& ctx, const ApplyCliOptions& o,
                             const std::vector<ops::Endpoint>& targets) {
  if (!o.reset || o.dry_run || o.yes) return;
  ctx.require_confirmation(
      "Reset the 8I20 on " + names_of(targets) +
          " after a verified apply (or when a reset is pending)? The new EEPROM values become live at once",
      "reset not confirmed; nothing was sent (pass --yes in scripts)");
}

void print_many(Context& ctx, const Profile& profile, const std::string& file,
                const std::vector<ops::TargetRun>& runs, const params::ParamDb& db,
                const render::FleetRequest& request) {
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& run : runs) arr.push(render::run_json(run));
    auto j = app::Json::object();
    j.set("profile", profile.name)
        .set("file", file)
        .set("exit_code", ops::exit_code(ops::fleet_outcome(runs)));
    ctx.print_json(j.set("targets", std::move(arr)));
    return;
  }
  std::cout << "Profile " << profile.name << " (" << file << ") -> " << runs.size() << " targets\n";
  render::print_fleet(std::cout, runs, db, file, request);
}

// One card: the plan as soon as it is known, each write as it happens, then the report.
// `run` runs the apply (on a target it opens, or on a card already open).
using RunOne = std::function<ops::TargetRun(const ops::Activity&, const ops::PlanShown&)>;

void apply_single(Context& ctx, const Profile& profile, const std::string& file, const params::ParamDb& db,
                  const std::string& target, const RunOne& run_one) {
  const bool text = !ctx.options.json;
  if (text)
    std::cout << "Profile " << profile.name << " (" << file << ") -> " << target << "\n" << std::flush;
  bool plan_shown = false;
  const auto show_plan = [&](const profile::Plan& plan) {
    if (!text || plan.empty()) return;
    render::print_plan(std::cout, plan);
    std::cout << std::flush;
    plan_shown = true;
  };
  const auto show_write = [text](const std::string& what) {
    if (text && (what.rfind("writing", 0) == 0 || what.rfind("restoring", 0) == 0 || what == "resetting"))
      std::cout << "  " << what << "\n" << std::flush;
  };
  const auto run = run_one(show_write, show_plan);
  ctx.record(run.outcome);
  if (!text) {
    auto j = render::run_json(run);
    j.set("profile", profile.name).set("file", file);
    return ctx.print_json(j);
  }
  render::print_run(std::cout, run, db, file, plan_shown);
  if (!run.ok()) std::cerr << "i20: " << render::error_line(run) << "\n";
}

// The transaction's settings apply, undo and a fleet share.
void set_change_options(ops::ApplyRequest& request, const ApplyCliOptions& o) {
  request.dry_run = o.dry_run;
  request.reset = o.reset;
  request.backup_dir =
      o.backup_dir.empty() ? profile::default_backup_dir() : std::filesystem::path(o.backup_dir);
  if (!o.dry_run) check_output_dir(*request.backup_dir);  // before the first byte
}

void run_apply_command(Context& ctx, const ApplyCliOptions& o) {
  const auto& db = ctx.session().db();
  auto profile = load(ctx, db, o.file);
  if (!profile) return;
  if (!o.to.empty()) {
    try {
      profile = profile::retarget(*profile, *profile::parse_memory(o.to), db);
    } catch (const profile::ProfileError& e) {
      return report_invalid(ctx, o.file, e);
    }
  }
  const auto targets = targets_of(ctx, o.targets);
  auto request = apply_request(ctx, *profile, db, o.force, o.allow_unverified);
  set_change_options(request, o);
  // The rules that need no card: nothing is sent when they refuse.
  const ops::ProfileApply apply(request);
  require_reset_confirmed(ctx, o, targets);
  if (targets.size() == 1) {
    const auto& target = targets.front();
    return apply_single(
        ctx, *profile, o.file, db, target.text,
        [&](const ops::Activity& a, const ops::PlanShown& p) { return apply.run_on(target, a, p); });
  }
  FleetProgress progress(targets, !ctx.options.json && isatty(STDERR_FILENO));
  const auto runs = apply.run_on(targets, progress.activity());
  progress.stop();
  print_many(ctx, *profile, o.file, runs, db, {o.reset, o.dry_run});
  ctx.record(ops::fleet_outcome(runs));
}

// ------------------------------------------------------------------ undo
struct UndoOptions {
  ApplyCliOptions apply;  // file: the backup; targets: the one card
  bool last = false;
};

// The backup back onto the card through apply's own transaction: validated against the
// card (the measured bus included), the card's current values backed up first, the plan
// (the card against the backup) shown before any write, verified, restored on failure. The
// backup must be this card's (lib/ops/undo): its origin is checked before the plan.
void run_undo(Context& ctx, const UndoOptions& o) {
  if (o.last == !o.apply.file.empty())
    throw UsageError(o.last ? "give either a BACKUP file or --last, not both"
                            : "name the BACKUP file to restore, or pass --last for the unit's newest backup");
  const auto& db = ctx.session().db();
  const auto targets = targets_of(ctx, o.apply.targets);
  if (targets.size() != 1) throw UsageError("undo restores one card: give a single --target");
  const auto& target = targets.front();
  require_reset_confirmed(ctx, o.apply, targets);
  const auto dir =
      o.apply.backup_dir.empty() ? profile::default_backup_dir() : std::filesystem::path(o.apply.backup_dir);
  if (!o.last && !load(ctx, db, o.apply.file)) return;  // a bad file is bad input before the link opens
  // The card names its unit; nothing but its identity is read before the backup is judged.
  auto amp = ctx.session().open(target, db);
  ops::BackupChoice choice;
  try {
    choice = o.last ? ops::newest_valid_backup(dir, *amp) : ops::backup_file(o.apply.file, db);
  } catch (const profile::ProfileError& e) {
    return report_invalid(ctx, o.apply.file, e);
  }
  const auto forced = ops::check_backup_origin(choice, *amp, o.apply.force);
  const std::string file = choice.file.string();
  auto backup = choice.backup;
  backup.name = "undo";  // names the backup this change takes in turn: "...-undo-unit00012345.yaml"
  auto request = apply_request(ctx, backup, db, o.apply.force, o.apply.allow_unverified);
  set_change_options(request, o.apply);
  const ops::ProfileApply apply(request);
  if (!ctx.options.json) {
    for (const auto& s : choice.skipped) std::cerr << "i20: note: passed over " << s << "\n";
    for (const auto& f : forced) std::cerr << "i20: warning: restoring anyway (--force): " << f << "\n";
    std::cout << "Undo: restoring the values saved in " << file << "\n";
  }
  apply_single(ctx, backup, file, db, target.text, [&](const ops::Activity& a, const ops::PlanShown& p) {
    if (a) a("connecting");
    return apply.run_on(*amp, a, p);
  });
}

// ------------------------------------------------------------------ save
struct SaveCliOptions {
  std::string file;
  std::vector<std::string> targets;
  std::vector<std::string> names;
  std::string name;
  bool overwrite = false;
};

// Whole or not at all: a full disk leaves no 0-byte file that looks like a setup.
void write_new_file(const std::string& file, const std::string& text, bool overwrite) {
  write_file_atomically(file, text, overwrite);
}

// Refused before the link opens: an existing file, a name not in the database or read-only.
void check_save_request(const SaveCliOptions& o, const params::ParamDb& db) {
  check_output_file(o.file, o.overwrite);
  ops::check_save_names(o.names, db);
}

void run_save(Context& ctx, const SaveCliOptions& o) {
  const auto& db_base = ctx.session().db();
  check_save_request(o, db_base);
  const auto amp = open_amp(ctx, o.targets, db_base);
  profile::SaveOptions save;
  save.name = !o.name.empty() ? o.name
              : o.file == "-" ? "saved"
                              : std::filesystem::path(o.file).stem().string();
  save.notes = "Saved with `i20 profile save`. Apply this file to write these values back.";
  const auto [saved, yaml] = ops::save_card(*amp, o.names, save, o.file);
  if (o.file == "-") {
    std::cout << yaml;
    return;
  }
  write_new_file(o.file, yaml, o.overwrite);
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("file", o.file).set("card", amp->describe()).set("values", saved.settings.size());
    return ctx.print_json(j);
  }
  const std::string flags = amp->endpoint().flags();
  std::cout << "Saved " << saved.settings.size() << " values of " << amp->describe() << " to " << o.file
            << "\nCompare a card with it: `i20 " << flags << " profile diff " << o.file
            << "`; write it back: `i20 " << flags << " profile apply " << o.file << "`\n";
}

// ------------------------------------------------------------------ registration
CLI::Option* add_target_option(CLI::App* cmd, std::vector<std::string>& targets, bool many) {
  const std::string help =
      std::string(many ? "The 8I20s, repeatable (instead of --port/--sim); each line in its own thread, the "
                         "targets of one line one after another. "
                       : "The 8I20 (instead of --port/--sim). ") +
      "Forms: " + ops::kEndpointForms;
  auto* opt = cmd->add_option("--target,-t", targets, help);
  if (!many) opt->expected(1);
  return opt;
}

void register_validate(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<ValidateOptions>();
  auto* cmd = profile.add_subcommand(
      "validate",
      "Check profiles against the parameter database and the manual's cross-parameter rules. With cards "
      "(--target, repeatable, or --port/--sim) it runs apply's own checks as a dry run on each: the card's "
      "values, the measured bus, a safe write order, the card's write rules; nothing is written. Without a "
      "card it says which rules were not judged. Exit 0 valid, 2 a file cannot be read, 3 apply would be "
      "refused, 1 a card not reached");
  cmd->add_option("FILE", o->files, "Profile files (YAML), or names of shipped profiles")
      ->required()
      ->transform(profile_file());
  add_target_option(cmd, o->targets, true);
  cmd->add_flag("--force", o->force,
                "Judge as apply --force does: guarded parameters (NVBAUDRATE) and thresholds at or below the "
                "measured bus are warnings, not errors");
  cmd->add_flag("--allow-unverified", o->allow_unverified,
                "Judge as apply --allow-unverified does (working addresses the database does not confirm)");
  cmd->callback([&ctx, o] { run_validate(ctx, *o); });
}

void register_diff(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<DiffOptions>();
  auto* cmd = profile.add_subcommand(
      "diff",
      "The cards against a profile, parameter by parameter (one section per --target, read concurrently "
      "across "
      "lines). Exit codes as diff(1): 0 every card holds every value, 1 some value differs, 2 trouble (bad "
      "input, a card not reached, a value not readable as a fact), 130 interrupted");
  cmd->add_option("FILE", o->file, "Profile file (YAML), or the name of a shipped profile")
      ->required()
      ->transform(profile_file());
  add_target_option(cmd, o->targets, true);
  cmd->callback([&ctx, o] { run_diff(ctx, *o); });
}

// The options apply and undo share: how the change is made.
void add_change_options(CLI::App* cmd, ApplyCliOptions& o) {
  cmd->add_flag("--dry-run,-n", o.dry_run, "Read the card and print the plan; write nothing");
  cmd->add_option("--backup-dir", o.backup_dir,
                  "Where the backup of the card's values goes (default: $XDG_STATE_HOME/i20/backups, i.e. "
                  "~/.local/state/i20/backups)");
  cmd->add_flag(
      "--reset", o.reset,
      "Reset the card after a verified change, or when an earlier EEPROM write is still not live, so "
      "the EEPROM values are live at once (asks first)");
  cmd->add_flag("--yes,-y", o.yes, "Do not ask before --reset");
  cmd->add_flag("--force", o.force,
                "Allow guarded parameters (NVBAUDRATE), and BUSOVERV/BRAKEONV at or below the measured bus");
  cmd->add_flag("--allow-unverified", o.allow_unverified,
                "Write working (RAM) addresses the database does not confirm for this firmware");
}

void register_apply(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<ApplyCliOptions>();
  auto* cmd = profile.add_subcommand(
      "apply",
      "Validate against the card, back up its current values, write only what differs in a safe order, read "
      "every value back; on any failure or Ctrl-C restore the old values. Exit 0 applied and verified or "
      "nothing "
      "to do, 1 card not reached, 2 profile cannot be read, 3 refused by a rule (nothing written), 4 rolled "
      "back "
      "or state uncertain (cells named), 6 output (a backup, stdout) not written, 130 interrupted");
  cmd->add_option("FILE", o->file, "Profile file (YAML), or the name of a shipped profile")
      ->required()
      ->transform(profile_file());
  add_target_option(cmd, o->targets, true);
  cmd->add_option("--to", o->to, "Aim every entry at the EEPROM (nv), the working values (working) or both")
      ->check(CLI::IsMember({"nv", "working", "both"}));
  add_change_options(cmd, *o);
  cmd->callback([&ctx, o] { run_apply_command(ctx, *o); });
}

void register_undo(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<UndoOptions>();
  auto* cmd = profile.add_subcommand(
      "undo",
      "Put back the values a backup holds (the file apply wrote before it changed the card, or --last: the "
      "unit's newest in the backup directory), through apply's own transaction: the plan (the card against "
      "the backup) first, then the writes, verified; the current values are backed up in turn. Exit codes as "
      "apply's");
  cmd->add_option("BACKUP", o->apply.file, "A backup file apply wrote (i20-backup-...yaml)");
  cmd->add_flag("--last", o->last, "The newest backup of this card's unit number in the backup directory");
  add_target_option(cmd, o->apply.targets, false);
  add_change_options(cmd, o->apply);
  cmd->callback([&ctx, o] { run_undo(ctx, *o); });
}

void register_save(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<SaveCliOptions>();
  auto* cmd = profile.add_subcommand(
      "save",
      "Read the card into a profile (by default its EEPROM setup: thresholds, MAXCURRENT, gains): a backup "
      "anyone can diff and re-apply");
  cmd->add_option("FILE", o->file, "Profile file to write (- for stdout)")->required();
  add_target_option(cmd, o->targets, false);
  cmd->add_option("--param", o->names, "Save these parameters instead (repeatable)");
  cmd->add_option("--name", o->name, "The profile's name (default: the file name)");
  cmd->add_flag("--overwrite", o->overwrite, "Replace FILE if it exists");
  cmd->callback([&ctx, o] { run_save(ctx, *o); });
}

}  // namespace

void register_profile_commands(CLI::App& app, Context& ctx) {
  auto* profile = app.add_subcommand(
      "profile",
      "Motor profiles: validate, diff against cards, apply safely (backup, verify, rollback; many cards at "
      "once with --target), undo an apply from its backup, save a card. See profiles/README.md");
  profile->require_subcommand(1);
  register_validate(*profile, ctx);
  register_diff(*profile, ctx);
  register_apply(*profile, ctx);
  register_undo(*profile, ctx);
  register_save(*profile, ctx);
  register_profile_export(*profile, ctx);
  register_tune_command(app, ctx);
}

}  // namespace i20::cli
