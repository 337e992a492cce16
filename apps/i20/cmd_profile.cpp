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
#include "output_file.hpp"
#include "fleet_progress.hpp"
#include "interrupt.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/fleet.hpp"
#include "ops/read.hpp"
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

bool has_card(const Context& ctx, const std::vector<std::string>& targets) {
  return !targets.empty() || ctx.options.has_target();
}

// The one card validate/diff/save read (read-only: Ctrl-C may stop them anywhere).
std::unique_ptr<ops::Card> open_card(Context& ctx, const std::vector<std::string>& targets,
                                     const params::ParamDb& db) {
  const auto endpoints = ops::resolve_endpoints(targets, ops::endpoint_from(ctx.options.target));
  if (endpoints.size() != 1) throw UsageError("this command reads one card: give a single --target");
  ops::OpenOptions open;
  open.link = ctx.options.link;
  return ops::Card::open(endpoints.front(), db, open, ops::Cancel(app::install_interrupt_handler()));
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
  ctx.exit_code = app::kBadInput;
  if (!ctx.options.json) return render::print_load_error(std::cerr, e, file);
  auto j = app::Json::object();
  j.set("file", file).set("valid", false).set("outcome", "invalid").set("exit_code", app::kBadInput);
  ctx.print_json(j.set("findings", render::load_error_json(e)));
}

// Loads FILE, or reports why not. Nothing is sent to a card before this succeeds.
std::optional<Profile> load(Context& ctx, const params::ParamDb& db, const std::string& file) {
  auto loaded = try_load(db, file);
  if (loaded.error) report_invalid(ctx, file, *loaded.error);
  return loaded.profile;
}

// ------------------------------------------------------------------ validate
struct ValidateOptions {
  std::vector<std::string> files;
  std::vector<std::string> targets;
  bool force = false;
};

// What the rules compare, as read from the card: only facts (a working cell whose address
// is not confirmed for this firmware is judged by its default, as without a card).
profile::RawValues read_for_rules(ops::Card& card, const Profile& p) {
  std::vector<const params::Param*> params;
  const auto add = [&](const std::string& name) {
    const params::Param* param = card.db().find(name);
    if (param && std::find(params.begin(), params.end(), param) == params.end()) params.push_back(param);
  };
  for (const auto& s : p.settings) add(s.name);
  for (const auto& base : ops::rule_parameters())
    if (const params::Param* param = card.db().find(base)) {
      add(param->name);
      add(param->twin);
    }
  profile::RawValues values;
  for (const auto& r : ops::read_values(card, params))
    if (r.fact()) values[r.param->name] = *r.raw;
  return values;
}

// One file: findings printed as they are found (text), its entry returned (JSON).
app::Json validate_file(Context& ctx, const params::ParamDb& db, ops::Card* card, const std::string& file,
                        bool force, bool& valid) {
  auto j = app::Json::object();
  j.set("file", file);
  const auto loaded = try_load(db, file);
  if (!loaded.profile) {
    valid = false;
    if (!ctx.options.json) {
      render::print_load_error(std::cout, *loaded.error, file);
      std::cout << file << ": INVALID (cannot be loaded)\n";
    }
    return j.set("valid", false).set("findings", render::load_error_json(*loaded.error));
  }
  profile::RawValues values;
  if (card) values = read_for_rules(*card, *loaded.profile);
  const auto findings = profile::validate(*loaded.profile, db, {card ? &values : nullptr, force, std::nullopt});
  valid = !profile::has_errors(findings);
  if (!ctx.options.json) {
    render::print_findings(std::cout, findings, file);
    std::cout << file << ": " << (valid ? "valid" : "INVALID") << " (" << render::findings_summary(findings)
              << (card ? ", checked against " + card->describe() : std::string()) << ")\n";
  }
  return j.set("valid", valid).set("findings", render::findings_json(findings));
}

void run_validate(Context& ctx, const ValidateOptions& o) {
  const auto db_base = app::load_database(ctx.options);
  std::unique_ptr<ops::Card> card;
  if (has_card(ctx, o.targets)) card = open_card(ctx, o.targets, db_base);
  const params::ParamDb& db = card ? card->db() : db_base;
  auto files = app::Json::array();
  bool all_valid = true;
  for (const auto& file : o.files) {
    bool valid = true;
    files.push(validate_file(ctx, db, card.get(), file, o.force, valid));
    all_valid = all_valid && valid;
  }
  if (!all_valid) ctx.exit_code = app::kBadInput;
  if (!ctx.options.json) return;
  auto j = app::Json::object();
  j.set("valid", all_valid).set("card", card ? app::Json(card->describe()) : app::Json());
  ctx.print_json(j.set("files", files));
}

// ------------------------------------------------------------------ diff
struct DiffOptions {
  std::string file;
  std::vector<std::string> targets;
};

void print_diff_summary(const std::vector<profile::DiffRow>& rows, const std::string& file,
                        const std::string& flags) {
  const auto differ = std::ranges::count_if(rows, [](const auto& r) { return !r.equal; });
  const auto nv = std::ranges::count_if(rows, [](const auto& r) { return !r.equal && r.nv; });
  if (differ == 0) {
    std::cout << "The card holds every value of the profile: applying it would write nothing.\n";
    return;
  }
  std::cout << differ << " of " << rows.size() << " values differ"
            << (nv ? " (" + std::to_string(nv) + " in the EEPROM: they take effect after a reset)" : "")
            << "; `i20 " << flags << " profile apply " << file << "` writes only those.\n";
}

void run_diff(Context& ctx, const DiffOptions& o) {
  const auto db_base = app::load_database(ctx.options);
  const auto profile = load(ctx, db_base, o.file);
  if (!profile) return;
  std::vector<std::string> names;
  try {
    for (const auto& w : profile::cell_writes(*profile, db_base)) names.push_back(w.cell);
  } catch (const profile::ProfileError& e) {  // a cell set twice, a target that cannot be met
    return report_invalid(ctx, o.file, e);
  }
  const auto card = open_card(ctx, o.targets, db_base);
  profile::RawValues values;
  for (const auto& r : ops::read_values(*card, names))
    if (r.fact()) values[r.param->name] = *r.raw;
  const auto rows = profile::diff(*profile, card->db(), values);
  if (ctx.options.json) {
    const auto differ = std::ranges::count_if(rows, [](const auto& r) { return !r.equal; });
    auto j = app::Json::object();
    j.set("file", o.file).set("profile", profile->name).set("card", card->describe());
    ctx.print_json(j.set("differ", differ).set("rows", render::diff_json(rows)));
    return;
  }
  std::cout << profile->name << " (" << o.file << ") against " << card->describe() << ":\n";
  render::print_diff(std::cout, rows);
  print_diff_summary(rows, o.file, card->endpoint().flags());
}

// ------------------------------------------------------------------ apply
struct ApplyCliOptions {
  std::string file;
  std::vector<std::string> targets;
  std::string to;  // retarget: nv | working | both
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
bool reset_confirmed(Context& ctx, const ApplyCliOptions& o, const std::vector<ops::Endpoint>& targets) {
  if (!o.reset || o.dry_run || o.yes) return true;
  if (ctx.confirm("Reset the 8I20 on " + names_of(targets) +
                  " after a verified apply (or when a reset is pending)? The new EEPROM values become live at once"))
    return true;
  std::cerr << "i20: reset not confirmed; nothing was sent (pass --yes in scripts)\n";
  ctx.exit_code = app::kBadInput;
  return false;
}

void print_many(Context& ctx, const Profile& profile, const std::string& file, const std::vector<ops::TargetRun>& runs,
                const params::ParamDb& db) {
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& run : runs) arr.push(render::run_json(run));
    auto j = app::Json::object();
    j.set("profile", profile.name).set("file", file).set("exit_code", ops::exit_code(ops::fleet_outcome(runs)));
    ctx.print_json(j.set("targets", std::move(arr)));
    return;
  }
  std::cout << "Profile " << profile.name << " (" << file << ") -> " << runs.size() << " targets\n";
  render::print_fleet(std::cout, runs, db, file);
}

// One card: the plan as soon as it is known, each write as it happens, then the report.
void apply_single(Context& ctx, const Profile& profile, const std::string& file, ops::ApplyJob job,
                  const ops::Endpoint& target) {
  const bool text = !ctx.options.json;
  if (text) std::cout << "Profile " << profile.name << " (" << file << ") -> " << target.text << "\n" << std::flush;
  bool plan_shown = false;
  job.transaction.on_plan = [&](const profile::Plan& plan) {
    if (!text || plan.empty()) return;
    render::print_plan(std::cout, plan);
    std::cout << std::flush;
    plan_shown = true;
  };
  const auto run = ops::run_apply(target, job, [text](const std::string& what) {
    if (text && (what.rfind("writing", 0) == 0 || what.rfind("restoring", 0) == 0 || what == "resetting"))
      std::cout << "  " << what << "\n" << std::flush;
  });
  ctx.exit_code = run.exit_code();
  if (!text) {
    auto j = render::run_json(run);
    j.set("profile", profile.name).set("file", file);
    return ctx.print_json(j);
  }
  render::print_run(std::cout, run, *job.db, file, plan_shown);
  if (!run.ok()) std::cerr << "i20: " << render::error_line(run) << "\n";
}

void run_apply_command(Context& ctx, const ApplyCliOptions& o) {
  const auto db = app::load_database(ctx.options);
  auto profile = load(ctx, db, o.file);
  if (!profile) return;
  if (!o.to.empty()) {
    try {
      profile = profile::retarget(*profile, *profile::parse_target(o.to), db);
    } catch (const profile::ProfileError& e) {
      return report_invalid(ctx, o.file, e);
    }
  }
  const auto targets = ops::resolve_endpoints(o.targets, ops::endpoint_from(ctx.options.target));
  ops::ApplyJob job;
  job.profile = &*profile;
  job.db = &db;
  job.write = {o.allow_unverified, o.force};
  ops::precheck(*profile, db, job.write);  // the rules that need no card: nothing is sent when they refuse
  if (!reset_confirmed(ctx, o, targets)) return;
  job.transaction.dry_run = o.dry_run;
  job.transaction.force = o.force;
  job.transaction.reset = o.reset;
  job.transaction.backup_dir =
      o.backup_dir.empty() ? profile::default_backup_dir() : std::filesystem::path(o.backup_dir);
  if (!o.dry_run) check_output_dir(*job.transaction.backup_dir);  // before the first byte
  job.transaction.when = std::chrono::system_clock::now();
  job.transaction.cancel = ops::Cancel(app::install_interrupt_handler());
  job.open.link = ctx.options.link;
  if (targets.size() == 1) return apply_single(ctx, *profile, o.file, job, targets.front());
  FleetProgress progress(targets, !ctx.options.json && isatty(STDERR_FILENO));
  const auto runs = ops::run_fleet(targets, job, progress.activity());
  progress.stop();
  print_many(ctx, *profile, o.file, runs, db);
  ctx.exit_code = ops::exit_code(ops::fleet_outcome(runs));
}

// ------------------------------------------------------------------ save
struct SaveCliOptions {
  std::string file;
  std::vector<std::string> targets;
  std::vector<std::string> names;
  std::string name;
  bool overwrite = false;
};

void write_new_file(const std::string& file, const std::string& text, bool overwrite) {
  if (!overwrite && std::filesystem::exists(file))
    throw UsageError(file + " exists; pass --overwrite to replace it (or choose another name)");
  std::ofstream out(file, std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw Error("cannot write " + file);
}

// The YAML of a saved card, proved to load back to exactly the values read before anyone
// relies on it.
std::string saved_yaml(const Profile& saved, const params::ParamDb& db, const std::string& file) {
  const std::string yaml = profile::to_yaml(saved, db);
  const Profile again = profile::load_profile_string(yaml, file, db);
  for (std::size_t i = 0; i < saved.settings.size(); ++i)
    if (again.settings.at(i).raw != saved.settings[i].raw)
      throw Error("the saved profile does not read back to the values read from the card");
  return yaml;
}

// Refused before the link opens: an existing file, a name not in the database or read-only.
void check_save_request(const SaveCliOptions& o, const params::ParamDb& db) {
  check_output_file(o.file, o.overwrite);
  for (const auto& n : o.names)
    if (!db.get(n).writable())
      throw UsageError(n + " is read-only: a profile holds settings that can be written back");
}

void run_save(Context& ctx, const SaveCliOptions& o) {
  const auto db_base = app::load_database(ctx.options);
  check_save_request(o, db_base);
  const auto card = open_card(ctx, o.targets, db_base);
  profile::SaveOptions save;
  save.name = !o.name.empty() ? o.name
              : o.file == "-" ? "saved"
                              : std::filesystem::path(o.file).stem().string();
  save.notes = "Saved with `i20 profile save`. Apply this file to write these values back.";
  const Profile saved = ops::save_profile(*card, o.names, save);
  const std::string yaml = saved_yaml(saved, card->db(), o.file);
  if (o.file == "-") {
    std::cout << yaml;
    return;
  }
  write_new_file(o.file, yaml, o.overwrite);
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("file", o.file).set("card", card->describe()).set("values", saved.settings.size());
    return ctx.print_json(j);
  }
  const std::string flags = card->endpoint().flags();
  std::cout << "Saved " << saved.settings.size() << " values of " << card->describe() << " to " << o.file
            << "\nCompare a card with it: `i20 " << flags << " profile diff " << o.file
            << "`; write it back: `i20 " << flags << " profile apply " << o.file << "`\n";
}

// ------------------------------------------------------------------ registration
CLI::Option* add_target_option(CLI::App* cmd, std::vector<std::string>& targets, bool many) {
  const std::string help =
      std::string(many ? "The 8I20s to apply to, repeatable; each in its own thread unless "
                         "they share a line. "
                       : "The 8I20 to read (instead of --port/--sim). ") +
      "Forms: " + ops::kEndpointForms;
  auto* opt = cmd->add_option("--target,-t", targets, help);
  if (!many) opt->expected(1);
  return opt;
}

void register_validate(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<ValidateOptions>();
  auto* cmd = profile.add_subcommand(
      "validate",
      "Check profiles against the parameter database and the manual's cross-parameter rules; with a card "
      "(--target or --port/--sim) rules use the card's values for what the profile does not set. Exit 2 if "
      "any profile has errors");
  cmd->add_option("FILE", o->files, "Profile files (YAML), or names of shipped profiles")
      ->required()
      ->transform(profile_file());
  add_target_option(cmd, o->targets, false);
  cmd->add_flag("--force", o->force, "Guarded parameters (NVBAUDRATE) are a warning, not an error");
  cmd->callback([&ctx, o] { run_validate(ctx, *o); });
}

void register_diff(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<DiffOptions>();
  auto* cmd = profile.add_subcommand("diff", "The card against a profile, parameter by parameter");
  cmd->add_option("FILE", o->file, "Profile file (YAML), or the name of a shipped profile")
      ->required()
      ->transform(profile_file());
  add_target_option(cmd, o->targets, false);
  cmd->callback([&ctx, o] { run_diff(ctx, *o); });
}

void register_apply(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<ApplyCliOptions>();
  auto* cmd = profile.add_subcommand(
      "apply",
      "Validate against the card, back up its current values, write only what differs in a safe order, read "
      "every value back; on any failure or Ctrl-C restore the old values. Exit 0 applied and verified or nothing "
      "to do, 1 card not reached, 2 profile cannot be read, 3 refused by a rule (nothing written), 4 rolled back "
      "or state uncertain (cells named), 130 interrupted");
  cmd->add_option("FILE", o->file, "Profile file (YAML), or the name of a shipped profile")
      ->required()
      ->transform(profile_file());
  add_target_option(cmd, o->targets, true);
  cmd->add_flag("--dry-run,-n", o->dry_run, "Read the card and print the plan; write nothing");
  cmd->add_option("--backup-dir", o->backup_dir,
                  "Where the backup of the card's values goes (default: $XDG_STATE_HOME/i20/backups, i.e. "
                  "~/.local/state/i20/backups)");
  cmd->add_option("--to", o->to, "Aim every entry at the EEPROM (nv), the working values (working) or both")
      ->check(CLI::IsMember({"nv", "working", "both"}));
  cmd->add_flag("--reset", o->reset,
                "Reset the card after a verified apply, or when an earlier EEPROM write is still not live, so the "
                "EEPROM values are live at once (asks first)");
  cmd->add_flag("--yes,-y", o->yes, "Do not ask before --reset");
  cmd->add_flag("--force", o->force,
                "Allow guarded parameters (NVBAUDRATE), and BUSOVERV/BRAKEONV at or below the measured bus");
  cmd->add_flag("--allow-unverified", o->allow_unverified,
                "Write working (RAM) addresses the database does not confirm for this firmware");
  cmd->callback([&ctx, o] { run_apply_command(ctx, *o); });
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
      "Motor profiles: validate, diff against a card, apply safely (backup, verify, rollback; many cards at "
      "once with --target), save a card. See profiles/README.md");
  profile->require_subcommand(1);
  register_validate(*profile, ctx);
  register_diff(*profile, ctx);
  register_apply(*profile, ctx);
  register_save(*profile, ctx);
  register_profile_export(*profile, ctx);
  register_tune_command(app, ctx);
}

}  // namespace i20::cli
