// SPDX-License-Identifier: GPL-2.0-or-later
// i20 profile export FILE --hal | --setsserial [--device hm2_7i96s.0.8i20.0.0] [-o OUT]
//
// Turns a profile's EEPROM values into what LinuxCNC sets them with (lib/profile/export):
// HAL `setp` lines for hostmot2, or `loadrt setsserial` lines. Offline: no card is touched.
// An invalid profile, a bad device name or an existing OUT is refused before anything is
// written.
#include "cmd_profile_export.hpp"

#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "change_render.hpp"
#include "context.hpp"
#include "output_file.hpp"
#include "profile/export.hpp"
#include "profile/loader.hpp"
#include "profile/validate.hpp"
#include "profile_lookup.hpp"

namespace i20::cli {
namespace {

struct ExportCliOptions {
  std::string file;
  bool hal = false;
  bool setsserial = false;
  std::string device = "hm2_7i96s.0.8i20.0.0";
  std::string out;
  bool overwrite = false;
  bool force = false;
};

// Loads and validates offline; nullopt (exit code set, findings printed) when not exportable.
std::optional<profile::Profile> valid_profile(Context& ctx, const params::ParamDb& db,
                                              const std::string& file, bool force) {
  try {
    auto p = profile::load_profile_file(file, db);
    profile::ValidationContext offline;  // no card: the rules judge by the database's defaults
    offline.force = force;
    const auto findings = profile::validate(p, db, offline);
    if (!profile::has_errors(findings)) return p;
    app::render::print_findings(std::cerr, findings, file);
    std::cerr << "i20: error: " << file << " is not valid (" << app::render::findings_summary(findings)
              << "); nothing exported\n";
  } catch (const profile::ProfileError& e) {
    app::render::print_load_error(std::cerr, e, file);
  }
  ctx.record(ops::Outcome::BadInput);
  return std::nullopt;
}

void write_file(const std::string& path, const std::string& text, bool overwrite) {
  write_file_atomically(path, text, overwrite);
}

app::Json values_json(const profile::Hostmot2Values& values, const ExportCliOptions& o) {
  auto settings = app::Json::array();
  for (const auto& s : values.settings) {
    auto j = app::Json::object();
    j.set("hal_parameter", o.device + "." + s.hal_name).set("value", s.value);
    settings.push(j.set("parameter", s.db_name).set("raw", s.db_raw));
  }
  auto skipped = app::Json::array();
  for (const auto& line : values.skipped) skipped.push(line);
  auto j = app::Json::object();
  j.set("file", o.file).set("format", o.hal ? "hal" : "setsserial").set("device", o.device);
  return j.set("settings", settings).set("skipped", skipped);
}

void run_export(Context& ctx, const ExportCliOptions& o) {
  profile::check_hal_device(o.device);
  check_output_file(o.out, o.overwrite);
  const auto& db = ctx.session().db();
  const auto p = valid_profile(ctx, db, o.file, o.force);
  if (!p) return;
  const profile::ExportOptions options{o.device, o.file};
  const std::string text =
      o.hal ? profile::hal_text(*p, db, options) : profile::setsserial_text(*p, db, options);
  const auto values = profile::hostmot2_values(*p, db);
  if (o.out.empty() || o.out == "-") {
    if (ctx.options.json) return ctx.print_json(values_json(values, o));
    std::cout << text;
    return;
  }
  write_file(o.out, text, o.overwrite);
  if (ctx.options.json) return ctx.print_json(values_json(values, o).set("output", o.out));
  std::cout << "Wrote " << values.settings.size() << (o.hal ? " setp" : " setsserial") << " lines for "
            << o.device << " to " << o.out << " (" << p->name
            << "; NV values take effect after the 8I20 is reset)\n";
  for (const auto& line : values.skipped) std::cout << "  skipped: " << line << "\n";
}

}  // namespace

void register_profile_export(CLI::App& profile, Context& ctx) {
  auto o = std::make_shared<ExportCliOptions>();
  auto* cmd = profile.add_subcommand(
      "export",
      "A profile's EEPROM values for LinuxCNC: HAL setp lines for hostmot2 (--hal) or loadrt setsserial "
      "lines "
      "(--setsserial), raw EEPROM words as hostmot2 takes them. Offline; exit 2 if the profile is invalid");
  cmd->add_option("FILE", o->file, "Profile file, or the name of a shipped profile (e.g. line-120v)")
      ->required()
      ->transform(profile_file());
  auto* hal = cmd->add_flag("--hal", o->hal, "setp lines for a HAL file");
  auto* sss =
      cmd->add_flag("--setsserial", o->setsserial, "loadrt setsserial cmd=\"set ...\" lines for halrun");
  hal->excludes(sss);
  cmd->add_option("--device", o->device,
                  "hostmot2 name of the 8I20: hm2_BOARD.N.8i20.PORT.CHANNEL, or hm2_8i20.XXXX with "
                  "use_serial_numbers=1 (default hm2_7i96s.0.8i20.0.0)");
  cmd->add_option("-o,--output", o->out, "Write to this file instead of stdout");
  cmd->add_flag("--overwrite", o->overwrite, "Replace the --output file if it exists");
  cmd->add_flag("--force", o->force, "Export guarded parameters (NVBAUDRATE) too; read why first");
  cmd->callback([&ctx, o] {
    if (o->hal == o->setsserial)
      throw Error("give exactly one of --hal or --setsserial", ErrorKind::BadInput);
    run_export(ctx, *o);
  });
}

}  // namespace i20::cli
