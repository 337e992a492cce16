// SPDX-License-Identifier: GPL-2.0-or-later
// i20 info | get | set | dump | reset | ports
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "change_render.hpp"
#include "context.hpp"
#include "csv_log.hpp"
#include "lbp/bytes.hpp"
#include "lbp/local.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/core/errors.hpp"
#include "ops/core/read.hpp"
#include "ops/reset.hpp"
#include "params/value.hpp"
#include "profile/finding.hpp"

namespace i20::cli {
namespace {

using params::Param;

// The value as a person reads it: engineering units, raw, or hex; "unknown (...)" when it
// is not a fact on this card.
std::string shown(const ops::Reading& r, bool raw, bool hex) {
  if (!r.raw) return ops::unknown_text(r);
  const auto& p = *r.param;
  std::string text =
      hex   ? lbp::hex_value(static_cast<std::uint64_t>(*r.raw) &
                                 ((p.width_bits == 32 ? 0xFFFFFFFFull : (1ull << p.width_bits) - 1)),
                             static_cast<int>(p.width_bits / 4))
      : raw ? std::to_string(*r.raw)
            : params::format_with_meaning(p, *r.raw);
  if (!r.confirmed) text += "  [read at an unconfirmed address: " + r.reason + "]";
  return text;
}

app::Json value_json(const ops::Reading& r) {
  const auto& p = *r.param;
  auto j = app::Json::object();
  j.set("name", p.name).set("raw", r.raw ? app::Json(*r.raw) : app::Json());
  if (!r.raw)
    j.set("value", app::Json());
  else if (p.unit.empty())
    j.set("value", *r.raw);
  else
    j.set("value", static_cast<double>(*r.raw) * p.scale);
  j.set("unit", p.unit).set("text", r.raw ? params::format_engineering(p, *r.raw) : ops::unknown_text(r));
  j.set("space", params::to_string(p.space)).set("address", p.address ? app::Json(*p.address) : app::Json());
  j.set("address_confirmed", r.confirmed).set("fact", r.fact());
  j.set("unknown_reason", r.reason.empty() ? app::Json() : app::Json(r.reason));
  j.set("twin", p.twin.empty() ? app::Json() : app::Json(p.twin));
  return j;
}

// ------------------------------------------------------------------ info
void run_info(Context& ctx) {
  auto& amp = ctx.amp();
  const auto& id = amp.identity();
  const auto& info = id.info;
  const auto& db = amp.db();
  if (ctx.options.json) {
    auto j = app::Json::object();
    j.set("target", amp.endpoint().text).set("card_name", info.card_name);
    j.set("unit_number", *info.unit_number).set("swrevision", *info.swrevision);
    j.set("working_map_confirmed", info.working_map_confirmed).set("lbp_version", info.lbp_version);
    j.set("unit_id", info.unit_id).set("unit_address", info.unit_address).set("lbp_status", info.lbp_status);
    j.set("lbp_status_text", lbp::local::status_text(info.lbp_status)).set("crc_errors", info.crc_errors);
    j.set("rpc_pitch", info.rpc_pitch).set("rpc_size", info.rpc_size).set("rpc_table", id.rpc_note);
    auto rpc = app::Json::array();
    for (const auto& n : id.rpc_confirmed) rpc.push(n);
    auto left = app::Json::array();
    for (const auto& m : id.modes_left) left.push(m);
    j.set("rpc_confirmed", std::move(rpc)).set("modes_left", std::move(left));
    ctx.print_json(j);
    return;
  }
  // Only the --sim endpoint is known to be the simulator; a card behind a port that reports
  // the simulator's revision is named by that fact alone.
  const bool sim_endpoint = amp.endpoint().kind == ops::Endpoint::Kind::Sim;
  const bool sim_revision = db.simulator_swrevision() == info.swrevision;
  const char* firmware_note = sim_endpoint   ? ", the built-in simulator"
                              : sim_revision ? ", the revision the simulator reports"
                                             : "";
  std::string rpc_names;
  for (const auto& n : id.rpc_confirmed) rpc_names += (rpc_names.empty() ? "" : " ") + n;
  std::cout << info.card_name << " on " << amp.endpoint().text << "\n"
            << "  unit number    " << *info.unit_number << " (" << lbp::hex_value(*info.unit_number, 8)
            << ")\n"
            << "  firmware       SWREVISION " << lbp::hex_value(*info.swrevision, 4) << " ("
            << *info.swrevision << ")" << firmware_note << "\n"
            << "  working map    "
            << (info.working_map_confirmed
                    ? "confirmed for this firmware: working parameters can be written"
                    : "NOT confirmed for this firmware: NV parameters work; run `i20 " + ctx.target_flags() +
                          " discover` for working ones")
            << "\n"
            << "  RPC table      " << info.rpc_size << " bytes, pitch " << int(info.rpc_pitch) << "; "
            << (rpc_names.empty() ? id.rpc_note : "confirms " + rpc_names + " (" + id.rpc_note + ")") << "\n"
            << "  LBP version    " << int(info.lbp_version) << "\n"
            << "  unit ID        " << int(info.unit_id) << "\n"
            << "  LBP status     " << lbp::hex_value(info.lbp_status, 2) << " ("
            << lbp::local::status_text(info.lbp_status) << ")\n"
            << "  CRC errors     " << int(info.crc_errors) << "\n";
  for (const auto& m : id.modes_left)
    std::cout << "  note           the card was left in " << m << " by an earlier session; switched it off\n";
}

// ------------------------------------------------------------------ get
struct GetOptions {
  std::vector<std::string> names;
  bool raw = false;
  bool hex = false;
  bool allow_unverified = false;
};

void run_get(Context& ctx, const GetOptions& o) {
  const auto& loaded = ctx.session().db();
  for (const auto& n : o.names) loaded.get(n);  // unknown names fail before the link opens
  auto& amp = ctx.amp();
  const auto readings =
      ops::read_values(amp, o.names, o.allow_unverified ? ops::Unconfirmed::Read : ops::Unconfirmed::Skip);
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& r : readings) arr.push(value_json(r));
    ctx.print_json(arr);
  } else {
    for (const auto& r : readings) std::cout << r.param->name << " = " << shown(r, o.raw, o.hex) << "\n";
  }
  const auto outcome = ops::reading_outcome(readings);
  ctx.record(outcome);
  if (outcome == ops::Outcome::Done) return;
  std::cerr
      << "i20: refused: not every value could be read as a fact on this card; run `i20 " << ctx.target_flags()
      << " discover` to confirm the working addresses, or pass --allow-unverified to see the raw words\n";
}

// ------------------------------------------------------------------ set
struct SetOptions {
  std::vector<std::string> assignments;
  ops::WriteOptions write;
  bool dry_run = false;
};

void run_set(Context& ctx, const SetOptions& o) {
  const auto& loaded = ctx.session().db();
  // Bad input and the rules that need no card refuse before the link is even opened.
  const ops::ValueChange change({.values = ops::named_values(o.assignments),
                                 .force = o.write.force,
                                 .allow_unverified = o.write.allow_unverified,
                                 .dry_run = o.dry_run,
                                 .cancel = ctx.session().cancel()},
                                loaded);
  auto& amp = ctx.amp();
  const bool show_progress = !ctx.options.json && change.profile().settings.size() > 1;
  const auto run = change.run_on(amp, [show_progress](const std::string& what) {
    if (show_progress && what.rfind("writing", 0) == 0) std::cerr << "i20: " << what << "\n";
  });
  ctx.record(run.outcome);
  if (ctx.options.json) return ctx.print_json(app::render::run_json(run));
  app::render::print_run(std::cout, run, amp.db(), "command line");
  if (!run.ok()) std::cerr << "i20: " << app::render::error_line(run) << "\n";
}

// ------------------------------------------------------------------ dump
void print_dump_table(const std::vector<ops::Reading>& values) {
  std::cout << std::left << std::setw(16) << "NAME" << std::setw(14) << "VALUE" << std::setw(12) << "RAW"
            << std::setw(16) << "NV TWIN"
            << "NOTE\n";
  for (const auto& v : values) {
    const auto& p = *v.param;
    const std::string twin = p.is_nv() ? "" : p.twin;
    std::cout << std::left << std::setw(16) << p.name << std::setw(14)
              << (v.raw ? params::format_engineering(p, *v.raw) : "unknown") << std::setw(12)
              << (v.raw ? std::to_string(*v.raw) : "-") << std::setw(16) << (twin.empty() ? "-" : twin)
              << (v.fact() ? "" : v.reason) << "\n";
  }
}

void print_dump_yaml(const std::vector<ops::Reading>& values) {
  std::cout << "# i20 dump\n";
  for (const auto& v : values) {
    const auto& p = *v.param;
    std::cout << "- {name: " << p.name << ", raw: " << (v.raw ? std::to_string(*v.raw) : "null")
              << ", value: \"" << (v.raw ? params::format_engineering(p, *v.raw) : ops::unknown_text(v))
              << "\", space: " << params::to_string(p.space)
              << ", address_confirmed: " << (v.confirmed ? "true" : "false") << "}\n";
  }
}

void print_dump_csv(const std::vector<ops::Reading>& values) {
  std::cout << "name,raw,value,unit,space,address,address_confirmed,note\n";
  for (const auto& v : values) {
    const auto& p = *v.param;
    std::cout << p.name << "," << (v.raw ? std::to_string(*v.raw) : "") << ","
              << csv_field(v.raw ? params::format_engineering(p, *v.raw) : "unknown") << "," << p.unit << ","
              << params::to_string(p.space) << "," << (p.address ? lbp::hex_value(*p.address, 4) : "") << ","
              << (v.confirmed ? "true" : "false") << "," << csv_field(v.fact() ? "" : v.reason) << "\n";
  }
}

void run_dump(Context& ctx, const std::string& format, bool allow_unverified) {
  auto& amp = ctx.amp();
  const auto values = ops::read_all(amp, allow_unverified ? ops::Unconfirmed::Read : ops::Unconfirmed::Skip);
  const std::string f = ctx.options.json ? "json" : format;
  if (f == "json") {
    auto arr = app::Json::array();
    for (const auto& v : values) arr.push(value_json(v));
    ctx.print_json(arr);
  } else if (f == "yaml") {
    print_dump_yaml(values);
  } else if (f == "csv") {
    print_dump_csv(values);
  } else {
    print_dump_table(values);
  }
}

// ------------------------------------------------------------------ reset
// Each finding as lib/ops said it: the refusal's closing line names the override (--force)
// once for them all.
void print_reset_findings(const ops::ResetJudgement& j) {
  for (const auto& f : j.findings)
    std::cerr << "  " << profile::to_string(f.severity) << ": " << (f.key.empty() ? "" : f.key + ": ")
              << f.message << " [" << f.rule << "]\n";
}

app::Json reset_json(const ops::ResetRun& run, const std::string& where) {
  auto names = [](const std::vector<std::string>& list) {
    auto arr = app::Json::array();
    for (const auto& n : list) arr.push(n);
    return arr;
  };
  auto findings = app::Json::array();
  for (const auto& f : run.judgement.findings)
    findings.push(app::Json::object()
                      .set("severity", profile::to_string(f.severity))
                      .set("key", f.key)
                      .set("rule", f.rule)
                      .set("message", app::render::finding_text(f)));
  return app::Json::object()
      .set("reset", run.done)
      .set("target", where)
      .set("outcome", run.done ? "done" : "refused")
      .set("made_live", names(run.judgement.pending))
      .set("live_state_unknown", names(run.judgement.unknown_live))
      .set("findings", std::move(findings));
}

void run_reset(Context& ctx, bool yes, bool force) {
  const std::string where = ctx.session().endpoint().text;  // asked before anything is sent
  if (!yes)
    ctx.require_confirmation("Reset the 8I20 on " + where + "? NV values become the working values",
                             "reset not confirmed; nothing was sent (pass --yes in scripts)");
  // The judgement (what the reset would make live, by the write transaction's rules) is
  // lib/ops's; this only reports it.
  const auto run = ops::reset_amp(ctx.amp(), force);
  const auto& j = run.judgement;
  ctx.record(run.outcome());
  if (!run.done) {
    if (ctx.options.json) return ctx.print_json(reset_json(run, where));
    std::cerr << "i20: refused: after the reset the card would run with EEPROM values the rules refuse; no "
                 "reset was sent (only reads):\n";
    print_reset_findings(j);
    std::cerr << "i20: fix them first (`i20 " << ctx.target_flags()
              << " set NAME=VALUE`), or pass --force if the supply will change first\n";
    return;
  }
  if (ctx.options.json) return ctx.print_json(reset_json(run, where));
  if (!j.findings.empty()) {
    std::cerr << "i20: reset despite these findings (--force):\n";
    print_reset_findings(j);
  }
  std::cout << "8I20 on " << where << " reset; it answers again and runs from its NV values";
  std::string live;
  for (const auto& n : j.pending) live += (live.empty() ? "" : ", ") + n;
  std::cout << (live.empty() ? " (none was pending)" : " (now live: " + live + ")") << "\n";
  if (!j.unknown_live.empty())
    std::cout << "  " << j.unknown_live.size()
              << " NV values have working twins this firmware cannot read; they were judged as if pending\n";
}

// ------------------------------------------------------------------ ports
void run_ports(Context& ctx) {
  const auto ports = ops::list_ports();
  if (ctx.options.json) {
    auto arr = app::Json::array();
    for (const auto& p : ports) {
      auto j = app::Json::object();
      j.set("device", p.device.string()).set("by_id", p.by_id.string()).set("driver", p.driver);
      j.set("vendor_id", p.vendor_id ? app::Json(*p.vendor_id) : app::Json());
      j.set("product_id", p.product_id ? app::Json(*p.product_id) : app::Json());
      j.set("manufacturer", p.manufacturer).set("product", p.product).set("serial", p.serial_number);
      arr.push(std::move(j));
    }
    ctx.print_json(arr);
    return;
  }
  if (ports.empty()) {
    std::cout << "no serial ports found; plug in the 3I22 (USB) and check `dmesg` for a new ttyUSB device\n";
    return;
  }
  for (const auto& p : ports) std::cout << p.summary() << "\n";
}

}  // namespace

void register_param_commands(CLI::App& app, Context& ctx) {
  auto* info = app.add_subcommand("info", "Card name, unit number, firmware, LBP status and CRC error count");
  info->callback([&ctx] { run_info(ctx); });

  auto get_options = std::make_shared<GetOptions>();
  auto* get = app.add_subcommand(
      "get", "Read parameters by name, in engineering units (e.g. i20 get NVBRAKEONV BUSV)");
  get->add_option("NAME", get_options->names, "Parameter names")->required();
  auto* raw = get->add_flag("--raw", get_options->raw, "Raw integers as on the wire");
  get->add_flag("--hex", get_options->hex, "Raw values in hexadecimal")->excludes(raw);
  get->add_flag(
      "--allow-unverified", get_options->allow_unverified,
      "Also read working parameters whose address is not confirmed for this firmware (shown as such)");
  get->footer(
      "Exit 0 when every value was read as a fact; 3 when one is unknown on this card (address not "
      "confirmed for its firmware).");
  get->callback([&ctx, get_options] { run_get(ctx, *get_options); });

  auto set_options = std::make_shared<SetOptions>();
  auto* set =
      app.add_subcommand("set",
                         "Write parameters: NAME=VALUE with units (NVBRAKEONV=370V, NVMAXCURRENT=7.5A; SI "
                         "symbols, exact case) or "
                         "raw card counts written raw:N (NVMAXCURRENT=raw:750 is 7.5 A); a bare number is "
                         "refused for a parameter "
                         "with a unit, and gains and masks take plain numbers (NVKQP=50). One transaction: "
                         "every value is checked against its range and the manual's rules "
                         "using the card's other values, cells that already hold their value are skipped, "
                         "the rest are written in "
                         "an order that keeps the thresholds consistent, read back, and restored if anything "
                         "fails. NV writes take "
                         "effect after a reset");
  set->footer(
      "Exit 0 written and verified (or nothing to do), 1 card not reached, 2 bad input, 3 refused by a "
      "rule (nothing written), 4 rolled back or state uncertain (cells named), 6 output not written, 130 "
      "Ctrl-C.");
  set->add_option("ASSIGNMENT", set_options->assignments, "NAME=VALUE pairs")->required();
  set->add_flag("--allow-unverified", set_options->write.allow_unverified,
                "Write working (RAM) addresses the database does not confirm for this firmware");
  set->add_flag(
      "--force", set_options->write.force,
      "Write guarded parameters (NVBAUDRATE, setpoints), and thresholds the bus voltage the card measures "
      "now makes unsafe (BUSOVERV, BRAKEONV or BRAKEOFFV at or below it, BUSUNDERV or BUSUNDERVMAX at or "
      "above it; working and NV)");
  set->add_flag("--dry-run", set_options->dry_run, "Read, check and plan; write nothing");
  set->callback([&ctx, set_options] { run_set(ctx, *set_options); });

  auto format = std::make_shared<std::string>("table");
  auto dump_unverified = std::make_shared<bool>(false);
  auto* dump = app.add_subcommand("dump", "Read every parameter in one pipelined pass");
  dump->add_option("--format", *format, "table, csv, json or yaml")
      ->check(CLI::IsMember({"table", "csv", "json", "yaml"}));
  dump->add_flag("--allow-unverified", *dump_unverified,
                 "Also read working parameters whose address is not confirmed for this firmware (marked)");
  dump->callback([&ctx, format, dump_unverified] { run_dump(ctx, *format, *dump_unverified); });

  auto yes = std::make_shared<bool>(false);
  auto reset_force = std::make_shared<bool>(false);
  auto* reset = app.add_subcommand(
      "reset",
      "Reset the 8I20 so NV values become live (asks first). The EEPROM values that differ from the working "
      "ones, and the measured bus, are read first and judged by the same rules as a write: refused (exit 3, "
      "no reset sent) when one would be unsafe live, e.g. NVBRAKEONV at or below the bus");
  reset->add_flag("--yes,-y", *yes, "Do not ask");
  reset->add_flag("--force", *reset_force,
                  "Reset even when the measured-bus rules refuse a value it would make live");
  reset->footer(
      "Exit 0 reset (or forced), 1 card not reached or did not come back, 2 not confirmed, 3 refused "
      "by a rule (nothing but reads sent).");
  reset->callback([&ctx, yes, reset_force] { run_reset(ctx, *yes, *reset_force); });

  auto* ports = app.add_subcommand("ports", "List serial ports (USB adapters with vendor, product, serial)");
  ports->callback([&ctx] { run_ports(ctx); });
}

}  // namespace i20::cli
