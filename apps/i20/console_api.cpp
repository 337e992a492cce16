// SPDX-License-Identifier: GPL-2.0-or-later
#include "console_api.hpp"

#include <sstream>

#include "change_render.hpp"
#include "faults_render.hpp"
#include "lbp/bytes.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/errors.hpp"
#include "ops/faults.hpp"
#include "ops/live_source.hpp"
#include "ops/pending.hpp"
#include "ops/read.hpp"
#include "ops/reset.hpp"
#include "ops/session.hpp"
#include "params/value.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;
using console::http::status;
using console::http::verb;

// How long CLEARFAULT may stay set, as `i20 clear-faults` waits by default.
constexpr std::chrono::milliseconds kClearWait{1000};

// The HTTP status of an outcome: the JSON body says the rest.
status status_of(ops::Outcome outcome) {
  switch (outcome) {
    case ops::Outcome::Done:
    case ops::Outcome::NothingToDo:
    case ops::Outcome::DryRun:
    case ops::Outcome::FaultsRemain: return status::ok;
    case ops::Outcome::BadInput: return status::bad_request;
    case ops::Outcome::Refused: return status::unprocessable_entity;
    case ops::Outcome::Interrupted: return status::service_unavailable;
    case ops::Outcome::Failed:
    case ops::Outcome::RolledBack:
    case ops::Outcome::Uncertain: return status::bad_gateway;  // the card, not the request
    case ops::Outcome::OutputLost: return status::internal_server_error;
  }
  return status::internal_server_error;
}

console::Response json_response(status s, const app::Json& body, const console::Request& request) {
  return console::make_response(s, body.dump(0), "application/json", request);
}

app::Json strings(const std::vector<std::string>& list) {
  auto arr = app::Json::array();
  for (const auto& s : list) arr.push(s);
  return arr;
}

std::string path_of(const console::Request& request) {
  return console::split_target(console::text(request.target())).first;
}

// One parameter as the Parameters page shows it: value, unit, range, twin, and whether it
// is a fact on this card; `pending` when the working twin holds something else.
app::Json param_json(const ops::Reading& r, bool pending) {
  const auto& p = *r.param;
  auto j = app::Json::object();
  j.set("name", p.name).set("space", params::to_string(p.space)).set("unit", p.unit);
  j.set("raw", r.raw ? app::Json(*r.raw) : app::Json());
  j.set("text", r.fact() ? params::format_with_meaning(p, *r.raw) : ops::unknown_text(r));
  j.set("fact", r.fact()).set("writable", p.writable());
  j.set("min", params::format_engineering(p, p.min)).set("max", params::format_engineering(p, p.max));
  j.set("twin", p.twin.empty() ? app::Json() : app::Json(p.twin));
  j.set("not_live_until_reset", pending).set("guard", p.guard).set("description", p.description);
  return j;
}

// The assignments of a change: one NAME=VALUE per line, as `i20 set` takes them.
std::vector<std::string> assignments_of(const std::string& body) {
  std::vector<std::string> out;
  std::istringstream in(body);
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) out.push_back(line);
  }
  if (out.empty()) throw UsageError("no change given: send NAME=VALUE lines (e.g. NVBRAKEONV=370V)");
  return out;
}

app::Json bit_labels(const std::vector<F::ReportLine>& lines) {
  auto arr = app::Json::array();
  for (const auto& line : lines) arr.push(bit_label(line));
  return arr;
}

}  // namespace

ConsoleApi::ConsoleApi(ops::Session& session) : session_(session) {}
ConsoleApi::~ConsoleApi() = default;

ops::LiveSource& ConsoleApi::live() {
  if (!live_) live_ = ops::make_live_source(session_, ops::LiveMode::Registers);
  return *live_;
}

console::Response ConsoleApi::handle(const console::Request& request) {
  const auto path = path_of(request);
  const bool get = request.method() == verb::get;
  try {
    if (get && path == "/api/overview") return overview(request);
    if (get && path == "/api/params") return params(request);
    if (get && path == "/api/faults") return faults(request);
    if (!get && path == "/api/preview") return change(request, true);
    if (!get && path == "/api/apply") return change(request, false);
    if (!get && path == "/api/clear-faults") return clear(request);
    if (!get && path == "/api/reset") return reset(request);
  } catch (...) {
    return failure(request);
  }
  return console::error_response(status::not_found, "no such API: " + path, request);
}

console::Response ConsoleApi::failure(const console::Request& request) {
  const auto report = session_.fail();
  auto lines = app::Json::array();
  for (const auto& line : report.lines)
    lines.push(app::Json::object().set("label", line.label).set("message", line.message));
  auto j = app::Json::object();
  j.set("outcome", ops::to_string(report.outcome)).set("lines", std::move(lines));
  if (live_) live_->reconnect();  // the next read opens the line again
  return json_response(status_of(report.outcome), j, request);
}

console::Response ConsoleApi::overview(const console::Request& request) {
  auto& card = session_.card();
  const auto& id = card.identity();
  const auto& info = id.info;
  const auto r = live().read();
  const auto values = ops::read_all(card);
  profile::RawValues facts;
  for (const auto& v : values)
    if (v.fact()) facts[v.param->name] = *v.raw;
  auto j = app::Json::object();
  j.set("target", card.endpoint().text).set("simulator", card.endpoint().kind == ops::Endpoint::Kind::Sim);
  j.set("card", card.describe()).set("card_name", info.card_name);
  j.set("unit_number", lbp::hex_value(*info.unit_number, 8));
  j.set("swrevision", lbp::hex_value(*info.swrevision, 4));
  j.set("working_map_confirmed", info.working_map_confirmed).set("rpc_table", id.rpc_note);
  j.set("modes_left", strings(id.modes_left));
  j.set("readings", readings_json(r));
  j.set("fault", report_json(F::fault_report(r.fault, r.faultmask), &r));
  j.set("status", report_json(live_status_report(r)));
  j.set("pending", strings(ops::pending_nv_values(card.db(), facts)));
  return json_response(status::ok, j, request);
}

console::Response ConsoleApi::params(const console::Request& request) {
  auto& card = session_.card();
  const auto values = ops::read_all(card);
  profile::RawValues facts;
  for (const auto& v : values)
    if (v.fact()) facts[v.param->name] = *v.raw;
  const auto pending = ops::pending_nv_values(card.db(), facts);
  auto arr = app::Json::array();
  for (const auto& v : values) {
    const auto& p = *v.param;
    const bool is_pending =
        std::find(pending.begin(), pending.end(), p.is_nv() ? p.name : p.twin) != pending.end();
    arr.push(param_json(v, is_pending));
  }
  return json_response(status::ok, app::Json::object().set("params", std::move(arr)), request);
}

console::Response ConsoleApi::faults(const console::Request& request) {
  const auto r = live().read();
  auto j = app::Json::object();
  j.set("target", live().describe()).set("method", live().method());
  j.set("fault", report_json(F::fault_report(r.fault, r.faultmask), &r));
  j.set("status", report_json(live_status_report(r))).set("readings", readings_json(r));
  return json_response(status::ok, j, request);
}

console::Response ConsoleApi::change(const console::Request& request, bool dry_run) {
  const auto& loaded = session_.db();
  // Bad input and the rules that need no card refuse before anything is sent, as `i20 set`.
  const auto profile =
      ops::profile_from_assignments(assignments_of(request.body()), loaded, ops::ValueSyntax::Engineering);
  ops::precheck(profile, loaded, {});
  auto& card = session_.card();
  const auto job = ops::make_apply_job(
      {.profile = &profile, .db = &card.db(), .dry_run = dry_run, .cancel = card.cancel()});
  const auto run = ops::run_apply_on(card, job);
  return json_response(status_of(run.outcome), app::render::run_json(run), request);
}

console::Response ConsoleApi::clear(const console::Request& request) {
  ops::check_offline(session_.db().get("CLEARFAULT"), 1, {});  // refused before anything is sent
  const auto res = ops::clear_faults(session_.card(), {}, kClearWait);
  const auto& r = res.after;
  auto j = app::Json::object();
  j.set("outcome", ops::to_string(res.outcome())).set("fault_before", lbp::hex_value(res.fault_before, 4));
  j.set("fault", report_json(F::fault_report(r.fault, r.faultmask), &r)).set("readings", readings_json(r));
  return json_response(status_of(res.outcome()), j, request);
}

console::Response ConsoleApi::reset(const console::Request& request) {
  const auto run = ops::reset_card(session_.card(), false);
  auto findings = app::Json::array();
  for (const auto& f : run.judgement.findings)
    findings.push(app::Json::object()
                      .set("severity", profile::to_string(f.severity))
                      .set("key", f.key)
                      .set("message", app::render::finding_text(f)));
  auto j = app::Json::object();
  j.set("outcome", ops::to_string(run.outcome())).set("reset", run.done);
  j.set("made_live", strings(run.judgement.pending)).set("findings", std::move(findings));
  if (live_) live_->reconnect();  // a reset card is identified again
  return json_response(status_of(run.outcome()), j, request);
}

std::string ConsoleApi::live_sample() {
  const auto now = std::chrono::duration_cast<std::chrono::milliseconds>(
                       std::chrono::system_clock::now().time_since_epoch())
                       .count();
  auto j = app::Json::object();
  j.set("t", static_cast<long long>(now));
  try {
    const auto r = live().read();
    j.set("busv", r.busv_v ? app::Json(*r.busv_v) : app::Json());
    j.set("temperature", r.temperature_c ? app::Json(*r.temperature_c) : app::Json());
    j.set("fault", lbp::hex_value(r.fault, 4)).set("status", lbp::hex_value(r.status, 4));
    j.set("fault_bits", bit_labels(F::fault_report(r.fault, r.faultmask).lines));
    j.set("status_bits", bit_labels(live_status_report(r).lines));
  } catch (const std::exception& e) {
    j.set("error", e.what());  // the page shows it; the next sample tries again
    live().reconnect();
  }
  return j.dump(0);
}

}  // namespace i20::cli
