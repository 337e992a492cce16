// SPDX-License-Identifier: GPL-2.0-or-later
#include "console_api.hpp"

#include <sstream>
#include <utility>

#include "change_render.hpp"
#include "console/gate.hpp"
#include "faults_render.hpp"
#include "lbp/bytes.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/core/errors.hpp"
#include "ops/core/pending.hpp"
#include "ops/core/read.hpp"
#include "ops/core/session.hpp"
#include "ops/faults.hpp"
#include "ops/reset.hpp"
#include "ops/watch/live_source.hpp"
#include "params/value.hpp"

namespace i20::cli {
namespace {

namespace F = i20::faults;
using console::http::status;
using console::http::verb;

// The request header an apply names its preview in.
constexpr const char* kPreviewHeader = "I20-Preview";
// How the page clears faults, for the "now:" lines that `i20 faults` words with its command.
constexpr const char* kClearButton = "Clear faults";

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

// ------------------------------------------------------------------ changes
// The writes a run plans, in order, each with the value the card holds: a preview and its
// apply must agree on every one for the page's "card holds / would write" table to be true.
std::vector<std::string> planned_writes(const ops::TargetRun& run) {
  std::vector<std::string> writes;
  if (!run.result) return writes;
  for (const auto& step : run.result->plan.steps)
    writes.push_back(step.cell + ": " + (step.card_raw ? std::to_string(*step.card_raw) : "unknown") +
                     " -> " + std::to_string(step.profile_raw));
  return writes;
}

// Only a preview that would write something can be applied.
bool would_write(const ops::TargetRun& run) {
  return run.outcome == ops::Outcome::DryRun && run.result && !run.result->plan.empty();
}

// `i20 set --json`'s report, and each cell's state in words for the page.
app::Json change_json(const ops::TargetRun& run) {
  auto j = app::render::run_json(run);
  auto states = app::Json::array();
  if (run.result)
    for (const auto& c : run.result->cells)
      states.push(app::Json::object()
                      .set("cell", c.cell)
                      .set("now", c.actual_text)
                      .set("state", app::render::cell_state_text(c)));
  j.set("cell_states", std::move(states));
  return j;
}

// An apply that does not match the live preview: 409, nothing sent to the card.
console::Response apply_refused(const std::string& why, const console::Request& request) {
  const std::string message = why + "; nothing was written: preview the values again, then apply";
  auto j = app::Json::object();
  j.set("outcome", ops::to_string(ops::Outcome::Refused))
      .set("ok", false)
      .set("summary", "REFUSED: " + message);
  j.set("lines",
        app::Json::array().push(app::Json::object().set("label", "refused").set("message", message)));
  return json_response(status::conflict, j, request);
}

// ------------------------------------------------------------------ faults in words
// A FAULT report as `i20 faults` prints it: per bit its heading, HAL pin, meaning, whether
// the cause is there now, causes and checks; the fault output and the register's notes.
app::Json fault_words(const F::Report& report, const Readings& live) {
  auto bits = app::Json::array();
  for (const auto& line : report.lines) {
    auto bit = app::Json::object();
    bit.set("heading", fault_heading(line)).set("severity", std::string(F::to_string(line.severity)));
    bit.set("hal_pin", line.linuxcnc_pin).set("meaning", line.meaning);
    bit.set("now", line.reserved ? std::string() : now_text(line, live, kClearButton));
    bit.set("causes", strings(line.causes)).set("checks", strings(line.checks));
    bits.push(std::move(bit));
  }
  auto j = app::Json::object();
  j.set("title", report.title).set("fault_output", fault_output_text(report));
  j.set("bits", std::move(bits)).set("notes", strings(report.notes));
  return j;
}

// A STATUS report as `i20 faults` prints it: heading, meaning, what was measured when a bit
// escalated, and the checks of the bits that need acting on.
app::Json status_words(const F::Report& report) {
  auto bits = app::Json::array();
  for (const auto& line : report.lines) {
    auto bit = app::Json::object();
    bit.set("heading", status_heading(line)).set("severity", std::string(F::to_string(line.severity)));
    bit.set("meaning", line.meaning).set("now", line.escalated ? line.evidence : std::string());
    bit.set("checks", status_checks_shown(line) ? strings(line.checks) : app::Json::array());
    bits.push(std::move(bit));
  }
  return app::Json::object().set("title", report.title).set("bits", std::move(bits));
}

// What a clear did, as `i20 clear-faults` says it: which bits it cleared, which remain
// latched and why, and the fault output now.
app::Json clear_words(const ops::ClearResult& res, const std::string& flags) {
  const auto& r = res.after;
  const auto cleared = res.cleared();
  const auto remaining = res.remaining();
  const bool nothing = res.fault_before == 0 && r.fault == 0;
  auto left = app::Json::array();
  for (const auto& line : remaining.lines)
    left.push(app::Json::object()
                  .set("heading", bit_label(line) + (line.masked ? " [masked]" : ""))
                  .set("meaning", line.meaning)
                  .set("why", why_remaining(line, r, flags))
                  .set("checks", strings(line.checks)));
  auto j = app::Json::object();
  const std::string took = "CLEARFAULT acknowledged in " + std::to_string(res.took.count()) + " ms";
  j.set("summary", nothing ? "No faults to clear: FAULT 0x0000 (" + took + ")"
                           : took + ": FAULT " + lbp::hex_value(res.fault_before, 4) + " -> " +
                                 lbp::hex_value(r.fault, 4) + ", " + std::to_string(cleared.lines.size()) +
                                 " cleared, " + std::to_string(remaining.lines.size()) + " remaining");
  j.set("cleared", bit_labels(cleared.lines)).set("remaining", std::move(left));
  j.set("fault_output", fault_output_text(remaining));
  j.set("advice", remaining.lines.empty() ? "" : "Fix the causes, then clear faults again.");
  return j;
}

}  // namespace

ConsoleApi::ConsoleApi(ops::Session& session, std::chrono::milliseconds live_interval)
    : session_(session), live_interval_(live_interval) {}
ConsoleApi::~ConsoleApi() = default;

ops::LiveSource& ConsoleApi::live() {
  if (!live_) {
    live_ = ops::make_live_source(session_, ops::LiveMode::Registers);
    sampler_ = std::make_unique<ops::LiveSampler>(*live_, live_interval_);
  }
  return *live_;
}

console::Response ConsoleApi::handle(const console::Request& request) {
  const auto path = path_of(request);
  const bool get = request.method() == verb::get;
  session_.begin_operation();  // each request gets the whole deadline, however long the page is open
  try {
    if (get && path == "/api/overview") return overview(request);
    if (get && path == "/api/params") return params(request);
    if (get && path == "/api/faults") return faults(request);
    if (!get && path == "/api/preview") return preview(request);
    if (!get && path == "/api/apply") return apply(request);
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
  // The next read opens the line again, after a failure of the card or its line only: input
  // the rules refused never reached the card (and reopening the built-in simulator would
  // start a fresh simulated card with its --sim-control world again).
  const bool input_refused =
      report.outcome == ops::Outcome::BadInput || report.outcome == ops::Outcome::Refused;
  if (live_ && !input_refused) live_->reconnect();
  return json_response(status_of(report.outcome), j, request);
}

console::Response ConsoleApi::overview(const console::Request& request) {
  auto& amp = session_.amp();
  const auto& id = amp.identity();
  const auto& info = id.info;
  const auto r = live().read();
  const auto values = ops::read_all(amp);
  profile::RawValues facts;
  for (const auto& v : values)
    if (v.fact()) facts[v.param->name] = *v.raw;
  auto j = app::Json::object();
  j.set("target", amp.endpoint().text).set("simulator", amp.endpoint().kind == ops::Endpoint::Kind::Sim);
  j.set("card", amp.describe()).set("card_name", info.card_name);
  j.set("unit_number", lbp::hex_value(*info.unit_number, 8));
  j.set("swrevision", lbp::hex_value(*info.swrevision, 4));
  j.set("working_map_confirmed", info.working_map_confirmed).set("rpc_table", id.rpc_note);
  j.set("modes_left", strings(id.modes_left));
  j.set("readings", readings_json(r));
  j.set("fault", report_json(F::fault_report(r.fault, r.faultmask), &r));
  j.set("status", report_json(live_status_report(r)));
  j.set("pending", strings(ops::pending_nv_values(amp.db(), facts)));
  return json_response(status::ok, j, request);
}

console::Response ConsoleApi::params(const console::Request& request) {
  auto& amp = session_.amp();
  const auto values = ops::read_all(amp);
  profile::RawValues facts;
  for (const auto& v : values)
    if (v.fact()) facts[v.param->name] = *v.raw;
  const auto pending = ops::pending_nv_values(amp.db(), facts);
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
  j.set("explained", app::Json::object()
                         .set("fault", fault_words(F::fault_report(r.fault, r.faultmask), r))
                         .set("status", status_words(live_status_report(r))));
  return json_response(status::ok, j, request);
}

ops::TargetRun ConsoleApi::run_change(const std::vector<std::string>& assignments, bool dry_run) {
  const auto& loaded = session_.db();
  // Bad input and the rules that need no card refuse before anything is sent, as `i20 set`.
  const ops::ValueChange change(
      {.values = ops::named_values(assignments), .dry_run = dry_run, .cancel = session_.cancel()}, loaded);
  return change.run_on(session_.amp());
}

console::Response ConsoleApi::preview(const console::Request& request) {
  preview_.reset();  // a new preview ends the last one, whatever this one ends in
  const auto assignments = assignments_of(request.body());
  const auto run = run_change(assignments, true);
  auto j = change_json(run);
  if (would_write(run)) {
    preview_ = Preview{console::make_token(), assignments, planned_writes(run)};
    j.set("preview_id", preview_->id);
  }
  return json_response(status_of(run.outcome), j, request);
}

// The page applies only what it previewed and shows; a stale page, a second click or a
// forged request must not write anything else. So an apply names its preview, carries the
// same lines, and is planned again exactly as the preview was (the same dry run) before the
// transaction writes: any difference refuses it with nothing sent but reads.
console::Response ConsoleApi::apply(const console::Request& request) {
  const auto previewed = std::exchange(preview_, std::nullopt);  // one apply per preview, however it ends
  const auto assignments = assignments_of(request.body());
  const auto id = console::text(request[kPreviewHeader]);
  if (!previewed || !console::same_secret(id, previewed->id))
    return apply_refused(
        "not the current preview (none was made, a newer one, an apply, a reset or a clear "
        "came since, or the request names another)",
        request);
  if (assignments != previewed->assignments)
    return apply_refused("the values differ from the ones previewed", request);
  const auto again = run_change(assignments, true);
  if (again.outcome != ops::Outcome::DryRun)
    return json_response(status_of(again.outcome), change_json(again), request);
  if (planned_writes(again) != previewed->writes)
    return apply_refused(
        "the card changed since the preview: the writes it shows are no longer the ones planned", request);
  const auto run = run_change(assignments, false);
  return json_response(status_of(run.outcome), change_json(run), request);
}

console::Response ConsoleApi::clear(const console::Request& request) {
  preview_.reset();                                // the card is not the one previewed any more
  const ops::FaultClear clear(session_.db(), {});  // refused before anything is sent
  const auto res = clear.run_on(session_.amp());
  const auto& r = res.after;
  auto j = app::Json::object();
  j.set("outcome", ops::to_string(res.outcome())).set("fault_before", lbp::hex_value(res.fault_before, 4));
  j.set("fault", report_json(res.remaining(), &r)).set("readings", readings_json(r));
  j.set("explained", clear_words(res, session_.endpoint().flags()));
  return json_response(status_of(res.outcome()), j, request);
}

console::Response ConsoleApi::reset(const console::Request& request) {
  preview_.reset();  // a reset makes other values live: preview again
  const auto run = ops::reset_amp(session_.amp(), false);
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
    live();
    const auto sample = sampler_->next();
    if (!sample.readings) {
      j.set("error", sample.error);  // the page shows it; a later sample tries again
      return j.dump(0);
    }
    const auto& r = *sample.readings;
    j.set("busv", r.busv_v ? app::Json(*r.busv_v) : app::Json());
    j.set("temperature", r.temperature_c ? app::Json(*r.temperature_c) : app::Json());
    j.set("fault", lbp::hex_value(r.fault, 4)).set("status", lbp::hex_value(r.status, 4));
    j.set("fault_bits", bit_labels(F::fault_report(r.fault, r.faultmask).lines));
    j.set("status_bits", bit_labels(live_status_report(r).lines));
  } catch (const std::exception& e) {
    j.set("error", e.what());  // not the card's (LiveSampler answers for those)
  }
  return j.dump(0);
}

}  // namespace i20::cli
