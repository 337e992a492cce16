// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 console`'s JSON API over the session's card. Every answer comes from the lib/ops use
// case the matching command runs, rendered with the same JSON helpers as its --json output:
//   GET  /api/overview      identity, firmware, map, readings, faults, pending NV values (info, faults)
//   GET  /api/params        every value with unit, range and twin (dump)
//   GET  /api/faults        decoded and explained (faults)
//   POST /api/preview       NAME=VALUE lines: the transaction's dry run (set --dry-run); a
//                           preview that would write something is given an id
//   POST /api/apply         the same lines and that id (header I20-Preview): written (set) only
//                           if they are the previewed lines and the card still plans the same writes
//   POST /api/clear-faults  (clear-faults)
//   POST /api/reset         judged, then reset, never forced (reset --yes)
//   WebSocket /api/live     FAULT, STATUS, bus voltage and temperature samples (watch)
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "console/router.hpp"

namespace i20::ops {
class Session;
class LiveSource;
class LiveSampler;
struct TargetRun;
}  // namespace i20::ops

namespace i20::cli {

class ConsoleApi : public console::Api {
 public:
  // `live_interval`: the live view's pace, which paces its retries of a lost card too.
  ConsoleApi(ops::Session& session, std::chrono::milliseconds live_interval);
  ~ConsoleApi() override;

  console::Response handle(const console::Request& request) override;
  std::string live_sample() override;

 private:
  console::Response overview(const console::Request& request);
  console::Response params(const console::Request& request);
  console::Response faults(const console::Request& request);
  console::Response preview(const console::Request& request);
  console::Response apply(const console::Request& request);
  // The one path of a change, previewed or written: `i20 set`'s checks and transaction.
  ops::TargetRun run_change(const std::vector<std::string>& assignments, bool dry_run);
  console::Response clear(const console::Request& request);
  console::Response reset(const console::Request& request);
  // The exception being handled, as the CLI reports it (the card settled), with its status.
  console::Response failure(const console::Request& request);
  ops::LiveSource& live();

  // The last preview that would write something: what an apply must match. One at a time;
  // an apply, a newer preview, a reset or a clear-faults ends it.
  struct Preview {
    std::string id;                        // random, so an apply cannot name a preview it did not get
    std::vector<std::string> assignments;  // the NAME=VALUE lines as previewed
    std::vector<std::string> writes;       // the planned writes, in order: "CELL: card -> new"
  };

  ops::Session& session_;
  std::chrono::milliseconds live_interval_;
  std::unique_ptr<ops::LiveSource> live_;
  std::unique_ptr<ops::LiveSampler> sampler_;  // the live view's reads of live_
  std::optional<Preview> preview_;
};

}  // namespace i20::cli
