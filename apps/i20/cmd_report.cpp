// SPDX-License-Identifier: GPL-2.0-or-later
// i20 report [-o FILE] [--json]: a field-service snapshot of one card, read-only, in one
// file a forum post or a support call can take as it is. Its `parameters` section is a
// profile: `i20 profile apply REPORT` writes the card's NV setup back.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "context.hpp"
#include "faults/report.hpp"
#include "lbp/bytes.hpp"
#include "ops/report.hpp"
#include "output_file.hpp"
#include "params/value.hpp"
#include "profile/timestamp.hpp"
#include "profile/writer.hpp"
#include "version/build_info.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;

struct ReportOptions {
  std::string out;
  bool overwrite = false;
};

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) out += c == '"' || c == '\\' ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

std::string names(const std::vector<std::string>& items) {
  std::string out = "[";
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i];
  return out + "]";
}

std::vector<std::string> bit_list(const F::Report& report) {
  std::vector<std::string> out;
  for (const auto& line : report.lines)
    out.push_back(line.reserved ? "bit" + std::to_string(line.bit) : line.name);
  return out;
}

app::Json array_of(const std::vector<std::string>& items) {
  auto arr = app::Json::array();
  for (const auto& item : items) arr.push(item);
  return arr;
}

std::string value_text(const ops::Reading& v) {
  return v.raw ? params::format_engineering(*v.param, *v.raw) : ops::unknown_text(v);
}

// The `report:` section, after the profile part: YAML the profile loader skips.
std::string report_section(const ops::ServiceReport& r) {
  const auto& info = r.identity.info;
  std::ostringstream y;
  y << "report:\n"
    << "  tool: " << quoted("i20tools " + std::string(build::kVersion)) << "\n"
    << "  time: " << profile::iso8601_utc(r.when) << "\n"
    << "  target: " << quoted(r.target) << "\n"
    << "  card:\n"
    << "    name: " << quoted(info.card_name) << "\n"
    << "    unit_number: " << lbp::hex_value(info.unit_number.value_or(0), 8) << "\n"
    << "    swrevision: " << lbp::hex_value(info.swrevision.value_or(0), 4) << "\n"
    << "    working_map_confirmed: " << (info.working_map_confirmed ? "true" : "false") << "\n"
    << "    lbp_version: " << int(info.lbp_version) << "\n"
    << "    lbp_status: " << lbp::hex_value(info.lbp_status, 2) << "\n"
    << "    crc_errors: " << int(info.crc_errors) << "\n"
    << "    rpc_table: " << quoted(r.identity.rpc_note) << "\n"
    << "    rpc_confirmed: " << names(r.identity.rpc_confirmed) << "\n"
    << "    modes_found_on: " << names(r.identity.modes_left) << "\n";
  if (r.faults) {
    const auto fault = F::fault_report(r.faults->fault, r.faults->faultmask);
    const auto status = F::status_report(r.faults->status);
    y << "  faults:\n"
      << "    fault: " << lbp::hex_value(r.faults->fault, 4) << "\n"
      << "    fault_bits: " << names(bit_list(fault)) << "\n"
      << "    status: " << lbp::hex_value(r.faults->status, 4) << "\n"
      << "    status_bits: " << names(bit_list(status)) << "\n";
    if (r.faults->faultmask) y << "    faultmask: " << lbp::hex_value(*r.faults->faultmask, 4) << "\n";
  } else {
    y << "  faults: {unknown: " << quoted(r.faults_error) << "}\n";
  }
  y << "  values:\n";
  for (const auto& v : r.values) {
    y << "    - {name: " << v.param->name << ", value: " << quoted(value_text(v));
    if (v.raw) y << ", raw: " << *v.raw;
    y << ", space: " << params::to_string(v.param->space);
    if (!v.reason.empty()) y << ", unknown_because: " << quoted(v.reason);
    y << "}\n";
  }
  y << "  nv_not_live_yet: " << names(r.not_live) << "\n";
  if (r.link)
    y << "  link: {exchanges: " << r.link->exchanges << ", commands: " << r.link->commands
      << ", bytes_sent: " << r.link->bytes_sent << ", bytes_received: " << r.link->bytes_received
      << ", timeouts: " << r.link->timeouts << ", crc_errors: " << r.link->crc_errors
      << ", resyncs: " << r.link->resyncs << ", retries: " << r.retries << "}\n";
  y << "  link_notes: [";
  for (std::size_t i = 0; i < r.link_notes.size(); ++i) y << (i ? ", " : "") << quoted(r.link_notes[i]);
  y << "]\n";
  return y.str();
}

app::Json report_json(const ops::ServiceReport& r) {
  const auto& info = r.identity.info;
  auto j = app::Json::object();
  j.set("tool", "i20tools " + std::string(build::kVersion)).set("time", profile::iso8601_utc(r.when));
  j.set("target", r.target);
  auto card = app::Json::object();
  card.set("name", info.card_name).set("unit_number", info.unit_number.value_or(0));
  card.set("swrevision", info.swrevision.value_or(0))
      .set("working_map_confirmed", info.working_map_confirmed);
  card.set("lbp_status", info.lbp_status)
      .set("crc_errors", info.crc_errors)
      .set("rpc_table", r.identity.rpc_note);
  j.set("card", std::move(card));
  if (r.faults) {
    auto f = app::Json::object();
    f.set("fault", r.faults->fault).set("fault_hex", lbp::hex_value(r.faults->fault, 4));
    f.set("status", r.faults->status).set("status_hex", lbp::hex_value(r.faults->status, 4));
    f.set("fault_bits", array_of(bit_list(F::fault_report(r.faults->fault, r.faults->faultmask))));
    f.set("status_bits", array_of(bit_list(F::status_report(r.faults->status))));
    j.set("faults", std::move(f));
  } else {
    j.set("faults", app::Json()).set("faults_unknown_because", r.faults_error);
  }
  auto values = app::Json::array();
  for (const auto& v : r.values) {
    auto e = app::Json::object();
    e.set("name", v.param->name)
        .set("raw", v.raw ? app::Json(*v.raw) : app::Json())
        .set("text", value_text(v));
    e.set("fact", v.fact()).set("space", params::to_string(v.param->space));
    values.push(std::move(e));
  }
  j.set("values", std::move(values));
  j.set("nv_not_live_yet", array_of(r.not_live));
  if (r.link)
    j.set("link", app::Json::object()
                      .set("exchanges", r.link->exchanges)
                      .set("commands", r.link->commands)
                      .set("timeouts", r.link->timeouts)
                      .set("crc_errors", r.link->crc_errors)
                      .set("resyncs", r.link->resyncs)
                      .set("retries", r.retries));
  return j;
}

void run_report(Context& ctx, const ReportOptions& o) {
  check_output_file(o.out, o.overwrite);  // before the first byte
  auto& amp = ctx.amp();
  const auto report = ops::gather_report(amp, std::chrono::system_clock::now());
  std::string text;
  if (ctx.options.json) {
    text = report_json(report).dump() + "\n";
  } else {
    auto profile = ops::report_profile(report, amp.db());
    profile.comments.insert(profile.comments.begin(),
                            {"i20 report: a field-service snapshot of one 8I20, read-only.",
                             "Its parameters section is a profile: `i20 " + amp.endpoint().flags() +
                                 " profile apply THIS_FILE` writes this NV setup back."});
    text = profile::to_yaml(profile, amp.db()) + report_section(report);
  }
  if (o.out.empty()) {
    std::cout << text;
    return;
  }
  write_file_atomically(o.out, text, o.overwrite);
  std::cerr << "i20: report of " << amp.describe() << " written to " << o.out << "\n";
}

}  // namespace

void register_report_command(CLI::App& app, Context& ctx) {
  auto o = std::make_shared<ReportOptions>();
  auto* cmd = app.add_subcommand(
      "report",
      "A field-service snapshot in one YAML file (or --json): identity, firmware and whether its map is "
      "confirmed, every parameter (NV values not live yet marked), FAULT/STATUS decoded, LBP status and CRC "
      "errors, link statistics, tool version and time. Read-only. Its parameters section is a profile: "
      "`i20 profile apply REPORT` writes the NV setup back");
  cmd->add_option("-o,--out", o->out, "Write the report to FILE instead of stdout");
  cmd->add_flag("--overwrite", o->overwrite, "Replace FILE if it exists");
  cmd->callback([&ctx, o] { run_report(ctx, *o); });
}

}  // namespace i20::cli
