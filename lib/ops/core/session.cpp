// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/session.hpp"

#include <cctype>
#include <cstdlib>

#include "device/errors.hpp"
#include "link/pipelined_link.hpp"
#include "ops/core/signals.hpp"

namespace i20::ops {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  return v ? std::string(v) : std::string();
}

std::string trimmed_upper(const std::string& s) {
  std::string out;
  for (char c : s)
    if (!std::isspace(static_cast<unsigned char>(c))) out.push_back(static_cast<char>(std::toupper(c)));
  return out;
}

unsigned baud_from_environment(const std::string& baud) {
  std::size_t used = 0;
  unsigned long rate = 0;
  try {
    rate = std::stoul(baud, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != baud.size() || baud.find_first_not_of("0123456789") != std::string::npos || rate == 0 ||
      rate > 12000000)
    throw UsageError("BAUDRATE is '" + baud + "', not a baud rate: setup mode needs BAUDRATE=115200");
  // WPD/RPD take the rate from BAUDRATE, but the 8I20 answers in setup mode at 115200 only
  // (manual, SETUP MODE): any other rate would read as a silent card, blamed on the cable.
  if (rate != 115200)
    throw UsageError("BAUDRATE is " + baud +
                     " but the 8I20's setup mode talks at 115200 baud only: set BAUDRATE=115200 or unset it");
  return static_cast<unsigned>(rate);
}

bool handling_card_state_error() {
  try {
    throw;
  } catch (const device::AmpStateError&) {
    return true;
  } catch (...) {
    return false;
  }
}

}  // namespace

void apply_legacy_environment(SessionOptions& o) {
  if (o.legacy == LegacyEnvironment::Ignore) return;
  const auto protocol = trimmed_upper(env("PROTOCOL"));
  if (!protocol.empty() && protocol != "LBP")
    throw UsageError("PROTOCOL is '" + env("PROTOCOL") + "' but the 8I20 speaks LBP: set PROTOCOL=LBP");
  if (o.has_target()) return;
  o.target.port = env("COMPORT");
  if (o.target.port.empty()) {
    if (o.legacy != LegacyEnvironment::Required) return;
    throw UsageError(
        "no port: set COMPORT (e.g. export COMPORT=/dev/ttyUSB0; `i20 ports` lists them) or pass --port, or "
        "--sim "
        "to try the built-in simulator");
  }
  if (const auto baud = env("BAUDRATE"); !baud.empty()) o.link.baud = baud_from_environment(baud);
}

params::ParamDb load_database(const SessionOptions& options) {
  auto db = params::ParamDb::builtin();
  if (!options.no_user_params)
    for (const auto& path : params::default_overlay_paths()) db.apply_overlay_file(path);
  for (const auto& path : options.params_files) db.apply_overlay_file(path);
  return db;
}

Session::Session(SessionOptions options, Cancel::Acknowledge acknowledge)
    : options_(std::move(options)), given_(options_.target), acknowledge_(std::move(acknowledge)) {
  install_stop_signals();
  apply_legacy_environment(options_);
}

Session::~Session() = default;

const params::ParamDb& Session::db() {
  if (!db_) db_ = std::make_unique<params::ParamDb>(load_database(options_));
  return *db_;
}

const Endpoint& Session::endpoint() {
  if (!endpoint_) endpoint_ = std::make_unique<Endpoint>(require_endpoint(options_.target));
  return *endpoint_;
}

std::vector<Endpoint> Session::targets(const std::vector<std::string>& named) const {
  // With --target, COMPORT is not a second target: only what the command line named counts.
  return resolve_endpoints(named, named.empty() ? endpoint_if_any() : endpoint_from(given_));
}

OpenOptions Session::open_options() const {
  OpenOptions open;
  open.link = options_.link;
  open.retry = options_.retry;
  return open;
}

Amp& Session::amp() {
  if (!amp_) amp_ = open(endpoint(), db());
  return *amp_;
}

std::unique_ptr<Amp> Session::open(const Endpoint& endpoint, const params::ParamDb& db) {
  return Amp::open(endpoint, db, open_options(), cancel());
}

Cancel Session::cancel() const {
  return Cancel(install_stop_signals(), acknowledge_);
}

bool Session::stop_requested() const {
  return ops::stop_requested();
}

void Session::begin_operation() {
  if (amp_) amp_->restart_deadline();
}

Settled Session::settle() {
  Settled settled;
  if (!amp_) return settled;
  const bool said = amp_->unsettled_said();
  try {
    if (const auto mode = amp_->settle(); !mode.empty())
      settled.note = MessageLine{
          "note", "the line failed while the card was in " + mode + "; it answered again and left it"};
  } catch (const device::AmpStateError&) {
    if (!said) throw;
    settled.outcome = Outcome::Uncertain;
  }
  return settled;
}

FailureReport failure_report_of_current_exception() {
  const Failure failure = failure_of_current_exception();
  return {failure.outcome, {failure.line}, failure.advice};
}

FailureReport Session::fail() {
  FailureReport report = failure_report_of_current_exception();
  // A AmpStateError is the settle's own verdict (or a mode already named): not again.
  if (!amp_ || handling_card_state_error()) return report;
  try {
    const auto settled = settle();
    if (settled.note) report.lines.push_back(*settled.note);
    if (settled.outcome != Outcome::Done) report.outcome = Outcome::Uncertain;
  } catch (const Error& e) {
    report.lines.push_back({"card state", e.what()});
    report.outcome = Outcome::Uncertain;
  }
  return report;
}

void Session::reconnect() {
  amp_.reset();
}

std::vector<std::string> Session::notes() const {
  if (!amp_) return {};
  auto notes = amp_->link().notes();
  if (const auto* pipelined = dynamic_cast<const link::PipelinedLink*>(&amp_->link())) {
    const auto& s = pipelined->statistics();
    notes.push_back("link: " + std::to_string(s.exchanges) + " exchanges, " + std::to_string(s.commands) +
                    " commands, " + std::to_string(s.bursts) + " bursts, " + std::to_string(s.bytes_sent) +
                    " bytes sent, " + std::to_string(s.bytes_received) + " received, " +
                    std::to_string(s.timeouts) + " timeouts, " + std::to_string(s.crc_errors) +
                    " CRC errors, " + std::to_string(s.resyncs) + " resyncs");
  }
  return notes;
}

}  // namespace i20::ops
