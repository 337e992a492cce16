// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 console`'s JSON API over the session's card. Every answer comes from the lib/ops use
// case the matching command runs, rendered with the same JSON helpers as its --json output:
//   GET  /api/overview      identity, firmware, map, readings, faults, pending NV values (info, faults)
//   GET  /api/params        every value with unit, range and twin (dump)
//   GET  /api/faults        decoded and explained (faults)
//   POST /api/preview       NAME=VALUE lines: the transaction's dry run (set --dry-run)
//   POST /api/apply         the same, written (set)
//   POST /api/clear-faults  (clear-faults)
//   POST /api/reset         judged, then reset, never forced (reset --yes)
//   WebSocket /api/live     FAULT, STATUS, bus voltage and temperature samples (watch)
#pragma once

#include <memory>
#include <string>

#include "console/router.hpp"

namespace i20::ops {
class Session;
class LiveSource;
}  // namespace i20::ops

namespace i20::cli {

class ConsoleApi : public console::Api {
 public:
  explicit ConsoleApi(ops::Session& session);
  ~ConsoleApi() override;

  console::Response handle(const console::Request& request) override;
  std::string live_sample() override;

 private:
  console::Response overview(const console::Request& request);
  console::Response params(const console::Request& request);
  console::Response faults(const console::Request& request);
  console::Response change(const console::Request& request, bool dry_run);
  console::Response clear(const console::Request& request);
  console::Response reset(const console::Request& request);
  // The exception being handled, as the CLI reports it (the card settled), with its status.
  console::Response failure(const console::Request& request);
  ops::LiveSource& live();

  ops::Session& session_;
  std::unique_ptr<ops::LiveSource> live_;
};

}  // namespace i20::cli
