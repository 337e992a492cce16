// SPDX-License-Identifier: GPL-2.0-or-later
// One session per program run (i20, wpd, rpd, a fleet): it resolves where the card is (the
// options, the environment WPD and RPD read, --sim-control), loads the database, opens and
// identifies the card on first use, owns the stop signals (ops/core/signals.hpp), leaves the card
// settled (no NV access or RPC memory mode), and turns every failure into one Outcome with
// the lines that say what happened. The apps parse arguments into SessionOptions and print
// what the session returns; the exit code comes from ops::exit_code alone.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ops/core/amp.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/failure.hpp"
#include "ops/core/outcome.hpp"
#include "params/param_db.hpp"

namespace i20::ops {

// The environment Mesa's WPD/RPD read (manual, "SETUP COMMUNICATION WITH 8I20"): COMPORT
// (COM1 or, here, a device path or eth:// URL), BAUDRATE (115200), PROTOCOL (LBP).
enum class LegacyEnvironment {
  Ignore,      // tests, programs that name their targets otherwise
  IfNoTarget,  // i20: COMPORT when no target is given on the command line
  Required,    // wpd, rpd: COMPORT is the port unless --port/--sim/--eth names one
};

struct SessionOptions {
  TargetFlags target;
  LinkSettings link;
  RetryPolicy retry;  // the programs' budget and deadline (timing.hpp); tests shorten them
  std::vector<std::string> params_files;
  bool no_user_params = false;
  LegacyEnvironment legacy = LegacyEnvironment::Ignore;

  bool has_target() const { return endpoint_from(target).has_value(); }
};

// Fills the port and baud from COMPORT/BAUDRATE unless a target was given, and rejects a
// PROTOCOL other than LBP. Throws UsageError with the fix.
void apply_legacy_environment(SessionOptions& options);

// The built-in database plus the per-user overlay and --params files, in that order.
params::ParamDb load_database(const SessionOptions& options);

// A session's verdict on its card at the end: Done when the card is settled, Uncertain when
// it did not confirm (and the command's own report already said so). `note` is set when
// a mode had to be left.
struct Settled {
  Outcome outcome = Outcome::Done;
  std::optional<MessageLine> note;
};

// A failure and what settling the card afterwards found: the lines to print in order, and
// the outcome of the whole (uncertain when the card did not confirm it was settled).
struct FailureReport {
  Outcome outcome = Outcome::Uncertain;
  std::vector<MessageLine> lines;
  Advice advice = Advice::None;
};
// The exception being handled as a report of its one line (no card to settle). Call from a
// catch block.
FailureReport failure_report_of_current_exception();

class Session {
 public:
  // Applies the legacy environment the options ask for (UsageError) and installs the stop
  // signals; `acknowledge` answers a stop that arrives while the card is being restored.
  explicit Session(SessionOptions options, Cancel::Acknowledge acknowledge = {});
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  // The options as resolved (COMPORT applied).
  const SessionOptions& options() const { return options_; }
  // The database as loaded (not resolved for any card): for parsing names and values
  // before anything is sent.
  const params::ParamDb& db();
  // The endpoint the options name (UsageError when they name none).
  const Endpoint& endpoint();
  std::optional<Endpoint> endpoint_if_any() const { return endpoint_from(options_.target); }
  // The cards a command names: every `--target` (with the global flags, refused when both
  // are given: resolve_endpoints), or the session's endpoint (COMPORT included).
  std::vector<Endpoint> targets(const std::vector<std::string>& named) const;
  // The card, opened and identified on first use.
  Amp& amp();
  bool card_open() const { return amp_ != nullptr; }
  // Opens another endpoint with this session's link settings and stop signals (a command
  // given --target): the caller owns it, and settles it by dropping it.
  std::unique_ptr<Amp> open(const Endpoint& endpoint, const params::ParamDb& db);
  // The open options every card of this session gets.
  OpenOptions open_options() const;

  // What every use case polls: set by SIGINT, SIGTERM, SIGHUP.
  Cancel cancel() const;
  bool stop_requested() const;

  // Ends the session's work on the card: a mode the line may have left on is left now
  // (Amp::settle). Throws AmpStateError when the card does not confirm and nothing has
  // said so yet; returns Uncertain when the command's own report already did.
  Settled settle();
  // From a catch block, with the session alive: the failure, then the card settled, because
  // a line that died may have left NV access or RPC memory mode on.
  FailureReport fail();

  // A new operation on the session's card (a console request, after minutes of others): its
  // deadline (retry.hpp) counts from now. Opens nothing.
  void begin_operation();

  // Drops the card so the next use opens it again (an adapter unplugged and replugged, or
  // the card reset).
  void reconnect();
  // Link and adapter notes (low-latency mode not available; the serial link's statistics),
  // for --verbose.
  std::vector<std::string> notes() const;

 private:
  SessionOptions options_;
  TargetFlags given_;  // the target as the command line named it, before the environment
  Cancel::Acknowledge acknowledge_;
  std::unique_ptr<params::ParamDb> db_;
  std::unique_ptr<Endpoint> endpoint_;
  std::unique_ptr<Amp> amp_;
};

}  // namespace i20::ops
