// SPDX-License-Identifier: GPL-2.0-or-later
// i20 inventory [--target T ...] [--profile FILE] [--json]: one row per amplifier of a fleet,
// read-only: identity, firmware and map confirmation, LinuxCNC name, faults, and whether it
// holds a profile (the comparison `profile diff` makes).
#include "cmd_inventory.hpp"

#include <CLI/CLI.hpp>
#include <iostream>

#include "change_render.hpp"
#include "context.hpp"
#include "faults/report.hpp"
#include "lbp/bytes.hpp"
#include "ops/inventory.hpp"
#include "ops/core/signals.hpp"
#include "profile/loader.hpp"
#include "profile_lookup.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;

struct InventoryOptions {
  std::vector<std::string> targets;
  std::string profile;
};

std::vector<std::string> fault_bits(const ops::InventoryRow& row) {
  std::vector<std::string> out;
  if (!row.faults) return out;
  for (const auto& line : F::fault_report(row.faults->fault, row.faults->faultmask).lines)
    out.push_back(line.reserved ? "bit" + std::to_string(line.bit) : line.name);
  return out;
}

std::string joined(const std::vector<std::string>& items, const std::string& none) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : ",") + item;
  return out.empty() ? none : out;
}

std::size_t differing(const ops::InventoryRow& row) {
  return static_cast<std::size_t>(std::ranges::count_if(row.diff, [](const auto& r) { return !r.equal; }));
}

std::string match_text(const ops::InventoryRow& row) {
  const auto m = row.matches();
  if (!m) return row.reached() ? "unknown" : "-";
  return *m ? "yes" : "no (" + std::to_string(differing(row)) + " differ)";
}

app::Json row_json(const ops::InventoryRow& row, bool with_profile) {
  auto j = app::Json::object();
  j.set("target", row.target.text).set("outcome", ops::to_string(row.outcome));
  j.set("exit_code", ops::exit_code(row.outcome)).set("error", row.error);
  j.set("linuxcnc_name", row.linuxcnc_name.empty() ? app::Json() : app::Json(row.linuxcnc_name));
  if (row.identity) {
    const auto& info = row.identity->info;
    j.set("card", row.card).set("name", info.card_name);
    j.set("unit_number", info.unit_number ? app::Json(*info.unit_number) : app::Json());
    j.set("swrevision", info.swrevision ? app::Json(*info.swrevision) : app::Json());
    j.set("working_map_confirmed", info.working_map_confirmed);
  }
  if (row.faults) {
    auto bits = app::Json::array();
    for (const auto& b : fault_bits(row)) bits.push(b);
    j.set("fault", row.faults->fault).set("status", row.faults->status).set("fault_bits", std::move(bits));
  } else {
    j.set("fault", app::Json()).set("faults_unknown_because", row.faults_error);
  }
  if (with_profile) {
    const auto m = row.matches();
    j.set("matches_profile", m ? app::Json(*m) : app::Json()).set("differ", differing(row));
    j.set("rows", app::render::diff_json(row.diff));
  }
  return j;
}

void print_table(const std::vector<ops::InventoryRow>& rows, bool with_profile) {
  std::vector<std::string> headers{"TARGET", "UNIT", "FIRMWARE", "MAP", "LINUXCNC", "FAULTS"};
  if (with_profile) headers.push_back("PROFILE");
  app::render::Table t(headers);
  for (const auto& row : rows) {
    std::vector<std::string> cells{row.target.text};
    if (!row.reached()) {
      cells.insert(cells.end(), {"-", "-", "-", row.linuxcnc_name.empty() ? "-" : row.linuxcnc_name,
                                 ops::to_string(row.outcome) + std::string(": ") + row.error});
    } else {
      const auto& info = row.identity->info;
      cells.push_back(info.unit_number ? lbp::hex_value(*info.unit_number, 8) : "?");
      cells.push_back(info.swrevision ? lbp::hex_value(*info.swrevision, 4) : "?");
      cells.push_back(info.working_map_confirmed ? "confirmed" : "unconfirmed");
      cells.push_back(row.linuxcnc_name.empty() ? "-" : row.linuxcnc_name);
      cells.push_back(row.faults ? joined(fault_bits(row), "none") : "unknown");
    }
    if (with_profile) cells.push_back(match_text(row));
    t.add(cells);
  }
  t.print(std::cout, "");
}

void run_inventory(Context& ctx, const InventoryOptions& o) {
  const auto& db = ctx.session().db();
  std::optional<profile::Profile> profile;
  if (!o.profile.empty()) {  // nothing is sent before the profile loads and names its cells
    profile = profile::load_profile_file(o.profile, db);
    (void)profile::cell_writes(*profile, db);
  }
  const auto targets = ctx.session().targets(o.targets);
  ops::InventoryJob job;
  job.db = &db;
  job.profile = profile ? &*profile : nullptr;
  job.open = ctx.session().open_options();
  job.cancel = ctx.session().cancel();
  const auto rows = ops::read_inventory(targets, job);
  ctx.record(ops::inventory_outcome(rows));
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& row : rows) arr.push(row_json(row, profile.has_value()));
    auto j = app::Json::object();
    j.set("profile", profile ? app::Json(profile->name) : app::Json()).set("exit_code", ctx.exit_code());
    return ctx.print_json(j.set("targets", std::move(arr)));
  }
  if (profile) std::cout << "Profile " << profile->name << " (" << o.profile << ")\n";
  print_table(rows, profile.has_value());
  const auto read = std::ranges::count_if(rows, [](const auto& r) { return r.outcome_ok(); });
  std::cout << "\n" << read << " of " << rows.size() << " amplifiers read; nothing was written\n";
}

}  // namespace

void register_inventory_command(CLI::App& app, Context& ctx) {
  auto o = std::make_shared<InventoryOptions>();
  auto* cmd = app.add_subcommand(
      "inventory",
      "One row per amplifier of a fleet: target, unit number, firmware and whether its map is confirmed, "
      "LinuxCNC name (SSERIAL channels), latched faults and, with --profile, whether the card holds the "
      "profile (the comparison `profile diff` makes). Read-only; concurrent across lines");
  cmd->add_option(
      "--target,-t", o->targets,
      std::string("The 8I20s to read, repeatable (or --port/--sim for one). Forms: ") + ops::kEndpointForms);
  cmd->add_option("--profile", o->profile, "Compare every card with this profile (a file or a shipped name)")
      ->transform(profile_file());
  cmd->callback([&ctx, o] { run_inventory(ctx, *o); });
}

}  // namespace i20::cli
