// i20 profile validate | diff | apply | save  (and `i20 tune`, cmd_tune.cpp)
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "amp_card_access.hpp"
#include "apply_run.hpp"
#include "cmd_profile_export.hpp"
#include "cmd_tune.hpp"
#include "context.hpp"
#include "fleet.hpp"
#include "interrupt.hpp"
#include "profile/diff.hpp"
#include "profile/loader.hpp"
#include "profile/save.hpp"
#include "profile/validate.hpp"
#include "profile/writer.hpp"
#include "profile_lookup.hpp"
#include "profile_render.hpp"
#include "target_spec.hpp"

namespace i20::cli {
namespace {

using profile::Profile;

// Working names of the parameters the manual's cross-parameter rules compare (as apply()
// reads them): validate with a card judges a profile against the card's own values.
constexpr std::array<const char*, 9> kRuleParams{
    "BRAKEONV", "BRAKEOFFV", "BUSOVERV", "BUSUNDERV", "MAXCURRENT", "KQP", "KDP", "KQI", "KDI"};

bool has_card(const Context& ctx, const std::vector<std::string>& targets) {
  return !targets.empty() || ctx.options.sim || !ctx.options.port.empty() || !ctx.options.eth.empty();
}

// The one card validate/diff/save read (read-only: Ctrl-C may stop them anywhere).
std::unique_ptr<Connection> open_card(Context& ctx, const std::vector<std::string>& targets,
                                      const params::ParamDb& db) {
  const auto specs = resolve_targets(targets, ctx.options);
  if (specs.size() != 1) throw UsageError("this command reads one card: give a single --target");
  return connect(specs.front(), db, &app::install_interrupt_handler());
}

AmpCardAccess card_access(Connection& c, const std::string& where) {
  CardAccessOptions options;
  options.where = where;
  return AmpCardAccess(*c.amp, options);
}

std::string target_text(Context& ctx, const std::vector<std::string>& targets) {
  return resolve_targets(targets, ctx.options).front().text;
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

// One read per name, keeping what answers (one unreadable cell fails a whole batch).
profile::RawValues read_each(AmpCardAccess& card, const std::vector<std::string>& names) {
  profile::RawValues values;
  for (const auto& name : names) {
    try {
      values.merge(card.read({name}));
    } catch (const std::exception&) {
    }
  }
  return values;
}

// Best effort, as apply() does it: a value that cannot be read is judged by its default.
// Working cells only where this firmware's map is confirmed: anything else would be a guess.
profile::RawValues read_for_rules(AmpCardAccess& card, const params::ParamDb& db, const Profile& p) {
  std::vector<std::string> names;
  const auto add = [&](const std::string& name) {
    const params::Param* param = db.find(name);
    if (param && param->address && db.address_confirmed(*param) &&
        std::find(names.begin(), names.end(), param->name) == names.end())
      names.push_back(param->name);
  };
  for (const auto& s : p.settings) add(s.name);
  for (const char* base : kRuleParams)
    if (const params::Param* param = db.find(base)) {
      add(param->name);
      add(param->twin);
    }
  try {
    return card.read(names);
  } catch (const std::exception&) {
    return read_each(card, names);
  }
}

// One file: findings printed as they are found (text), its entry returned (JSON).
app::Json validate_file(Context& ctx, const params::ParamDb& db, AmpCardAccess* card, const std::string& file,
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
  if (card) values = read_for_rules(*card, db, *loaded.profile);
  const auto findings = profile::validate(*loaded.profile, db, {card ? &values : nullptr, force});
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
  std::unique_ptr<Connection> card;
  std::optional<AmpCardAccess> access;
  if (has_card(ctx, o.targets)) {
    card = open_card(ctx, o.targets, db_base);
    access.emplace(card_access(*card, target_text(ctx, o.targets)));
  }
  const params::ParamDb& db = card ? card->db : db_base;
  auto files = app::Json::array();
  bool all_valid = true;
  for (const auto& file : o.files) {
    bool valid = true;
    files.push(validate_file(ctx, db, access ? &*access : nullptr, file, o.force, valid));
    all_valid = all_valid && valid;
  }
  if (!all_valid) ctx.exit_code = app::kBadInput;
  if (!ctx.options.json) return;
  auto j = app::Json::object();
  j.set("valid", all_valid).set("card", access ? app::Json(access->describe()) : app::Json());
  ctx.print_json(j.set("files", files));
}

// ------------------------------------------------------------------ diff
struct DiffOptions {
  std::string file;
  std::vector<std::string> targets;
};

void print_diff_summary(const std::vector<profile::DiffRow>& rows, const std::string& file) {
  const auto differ = std::ranges::count_if(rows, [](const auto& r) { return !r.equal; });
  const auto nv = std::ranges::count_if(rows, [](const auto& r) { return !r.equal && r.nv; });
  if (differ == 0) {
    std::cout << "The card holds every value of the profile: applying it would write nothing.\n";
    return;
  }
  std::cout << differ << " of " << rows.size() << " values differ"
            << (nv ? " (" + std::to_string(nv) + " in the EEPROM: they take effect after a reset)" : "")
            << "; `i20 profile apply " << file << "` writes only those.\n";
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
  auto access = card_access(*card, target_text(ctx, o.targets));
  const auto rows = profile::diff(*profile, card->db, access.read(names));
  if (ctx.options.json) {
    const auto differ = std::ranges::count_if(rows, [](const auto& r) { return !r.equal; });
    auto j = app::Json::object();
    j.set("file", o.file).set("profile", profile->name).set("card", access.describe());
    ctx.print_json(j.set("differ", differ).set("rows", render::diff_json(rows)));
    return;
  }
  std::cout << profile->name << " (" << o.file << ") against " << access.describe() << ":\n";
  render::print_diff(std::cout, rows);
  print_diff_summary(rows, o.file);
}

// ------------------------------------------------------------------ apply
struct ApplyCliOptions {
  std::string file;
  std::vector<std::string> targets;
  std::string to;  // retarget: nv | working | both
  std::string backup_dir = ".";
  bool dry_run = false;
  bool force = false;
  bool allow_unverified = false;
  bool reset = false;
  bool yes = false;
};

std::string names_of(const std::vector<TargetSpec>& targets) {
  std::string text;
  for (const auto& t : targets) text += (text.empty() ? "" : ", ") + t.text;
  return text;
}

// A reset makes the new EEPROM values live at once: asked before anything is sent.
bool reset_confirmed(Context& ctx, const ApplyCliOptions& o, const std::vector<TargetSpec>& targets) {
  if (!o.reset || o.dry_run || o.yes) return true;
  if (ctx.confirm("Reset the 8I20 on " + names_of(targets) +
                  " after a verified apply? The new EEPROM values become live at once"))
    return true;
  std::cerr << "i20: reset not confirmed; nothing was sent (pass --yes in scripts)\n";
  ctx.exit_code = app::kBadInput;
  return false;
}

void print_single(Context& ctx, const Profile& profile, const std::string& file, const TargetRun& run,
                  const params::ParamDb& db) {
  if (ctx.options.json) {
    auto j = render::run_json(run);
    j.set("profile", profile.name).set("file", file);
    ctx.print_json(j);
    return;
  }
  std::cout << "Profile " << profile.name << " (" << file << ") -> " << run.target << "\n";
  render::print_run(std::cout, run, db, file);
}

void print_many(Context& ctx, const Profile& profile, const std::string& file,
                const std::vector<TargetRun>& runs, const params::ParamDb& db) {
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& run : runs) arr.push(render::run_json(run));
    auto j = app::Json::object();
    j.set("profile", profile.name).set("file", file).set("exit_code", fleet_exit_code(runs));
    ctx.print_json(j.set("targets", std::move(arr)));
    return;
  }
  std::cout << "Profile " << profile.name << " (" << file << ") -> " << runs.size() << " targets\n";
  render::print_fleet(std::cout, runs, db, file);
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
  const auto targets = resolve_targets(o.targets, ctx.options);
  if (!reset_confirmed(ctx, o, targets)) return;
  ApplyJob job;
  job.profile = &*profile;
  job.db = &db;
  job.apply = {o.dry_run, o.force, o.reset, o.backup_dir, std::chrono::system_clock::now()};
  job.card.write = {o.allow_unverified, o.force};
  if (targets.size() == 1) {
    const auto run = run_apply(targets.front(), job);
    print_single(ctx, *profile, o.file, run, db);
    ctx.exit_code = run.exit_code;
    return;
  }
  const bool progress = !ctx.options.json && isatty(STDERR_FILENO);
  const auto runs = run_fleet(targets, job, {progress});
  print_many(ctx, *profile, o.file, runs, db);
  ctx.exit_code = fleet_exit_code(runs);
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
  if (o.file != "-" && !o.overwrite && std::filesystem::exists(o.file))
    throw UsageError(o.file + " exists; pass --overwrite to replace it (or choose another name)");
  for (const auto& n : o.names)
    if (!db.get(n).writable())
      throw UsageError(n + " is read-only: a profile holds settings that can be written back");
}

void run_save(Context& ctx, const SaveCliOptions& o) {
  const auto db_base = app::load_database(ctx.options);
  check_save_request(o, db_base);
  const auto card = open_card(ctx, o.targets, db_base);
  auto access = card_access(*card, target_text(ctx, o.targets));
  profile::SaveOptions save;
  save.name = !o.name.empty() ? o.name
              : o.file == "-" ? "saved"
                              : std::filesystem::path(o.file).stem().string();
  save.notes = "Saved with `i20 profile save`. Apply this file to write these values back.";
  const Profile saved = profile::save(access, card->db, o.names, save);
  const std::string yaml = saved_yaml(saved, card->db, o.file);
  if (o.file == "-") {
    std::cout << yaml;
    return;
  }
  write_new_file(o.file, yaml, o.overwrite);
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("file", o.file).set("card", access.describe()).set("values", saved.settings.size());
    return ctx.print_json(j);
  }
  std::cout << "Saved " << saved.settings.size() << " values of " << access.describe() << " to " << o.file
            << "\nCompare a card with it: `i20 profile diff " << o.file
            << "`; write it back: `i20 profile apply " << o.file << "`\n";
}

// ------------------------------------------------------------------ registration
CLI::Option* add_target_option(CLI::App* cmd, std::vector<std::string>& targets, bool many) {
  const std::string help =
      std::string(many ? "The 8I20s to apply to, repeatable; each in its own thread unless "
                         "they share a line. "
                       : "The 8I20 to read (instead of --port/--sim). ") +
      "Forms: " + kTargetForms;
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
  cmd->add_option("FILE", o->files, "Profile files (YAML), or names of shipped profiles")->required()->transform(profile_file());
  add_target_option(cmd, o->targets, false);
  cmd->add_flag("--force", o->force, "Guarded parameters (NVBAUDRATE) are a warning, not an error");
  cmd->callback([&ctx, o] { run_validate(ctx, *o); });
}

void register_diff(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<DiffOptions>();
  auto* cmd = profile.add_subcommand("diff", "The card against a profile, parameter by parameter");
  cmd->add_option("FILE", o->file, "Profile file (YAML), or the name of a shipped profile")->required()->transform(profile_file());
  add_target_option(cmd, o->targets, false);
  cmd->callback([&ctx, o] { run_diff(ctx, *o); });
}

void register_apply(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<ApplyCliOptions>();
  auto* cmd = profile.add_subcommand(
      "apply",
      "Validate against the card, back up its current values, write only what differs in a safe order, read "
      "every value back; on any failure restore the backup. Exit 0 applied and verified or nothing to do, 2 "
      "invalid profile, 3 refused by a safety rule, 4 rolled back (or rollback failed), 1 card not reached");
  cmd->add_option("FILE", o->file, "Profile file (YAML), or the name of a shipped profile")->required()->transform(profile_file());
  add_target_option(cmd, o->targets, true);
  cmd->add_flag("--dry-run,-n", o->dry_run, "Read the card and print the plan; write nothing");
  cmd->add_option("--backup-dir", o->backup_dir, "Where the backup of the card's values goes (default: .)");
  cmd->add_option("--to", o->to, "Aim every entry at the EEPROM (nv), the working values (working) or both")
      ->check(CLI::IsMember({"nv", "working", "both"}));
  cmd->add_flag("--reset", o->reset,
                "Reset the card after a verified apply so the EEPROM values are live at once (asks first)");
  cmd->add_flag("--yes,-y", o->yes, "Do not ask before --reset");
  cmd->add_flag("--force", o->force, "Allow guarded parameters (NVBAUDRATE)");
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
