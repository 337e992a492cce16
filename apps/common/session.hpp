// SPDX-License-Identifier: GPL-2.0-or-later
// What every app shares: the global options (where the 8I20 is, which database), and a
// session that loads the database and opens and identifies the card on first use, through
// lib/ops (the one endpoint policy).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "ops/card.hpp"
#include "ops/endpoint.hpp"
#include "params/param_db.hpp"

namespace CLI {
class App;
}

namespace i20::app {

struct GlobalOptions {
  ops::TargetFlags target;
  ops::LinkSettings link;
  std::vector<std::string> params_files;
  bool no_user_params = false;
  bool json = false;
  bool verbose = false;

  bool has_target() const { return ops::endpoint_from(target).has_value(); }
};

// Adds --port/--sim/--eth/... to an app (the i20 umbrella, wpd, rpd).
void add_target_options(CLI::App& app, GlobalOptions& options);
void add_database_options(CLI::App& app, GlobalOptions& options);

// The built-in database plus the per-user overlay and --params files, in that order.
params::ParamDb load_database(const GlobalOptions& options);

class Session {
 public:
  explicit Session(GlobalOptions options);
  ~Session();

  const GlobalOptions& options() const { return options_; }
  // The database as loaded (not resolved for any card): for parsing names and values
  // before anything is sent.
  const params::ParamDb& db();
  // The endpoint the options name (UsageError when they name none).
  const ops::Endpoint& endpoint();
  // The card, opened and identified on first use (Ctrl-C is its cancel input).
  ops::Card& card();
  bool card_open() const { return card_ != nullptr; }
  // Ends the session's work on the card: a mode the line may have left on is left now
  // (ops::Card::settle); throws CardStateError when the card does not confirm. Prints a
  // note to stderr when it had to leave one. Returns kCardState, saying nothing more, when
  // the card still does not confirm and the command's own report already said so.
  [[nodiscard]] int settle(const char* program);
  // From a catch (...) block, with the session still alive: reports the exception (one line,
  // its exit code), then settles the card, because a line that died may have left NV access
  // or RPC memory mode on. When the card does not confirm, a second line says so and the
  // exit code becomes 4 (the card's state is uncertain).
  int report_failure(const char* program);
  // Drops the card so the next use opens it again (after an adapter was unplugged and
  // replugged, or the card reset).
  void reconnect();
  // Link and adapter notes (e.g. low-latency mode not available), for --verbose.
  std::vector<std::string> notes() const;
  const link::Link* link_if_open() const;

 private:
  GlobalOptions options_;
  std::unique_ptr<params::ParamDb> db_;
  std::unique_ptr<ops::Endpoint> endpoint_;
  std::unique_ptr<ops::Card> card_;
};

}  // namespace i20::app
