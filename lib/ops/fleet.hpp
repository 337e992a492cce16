// SPDX-License-Identifier: GPL-2.0-or-later
// One profile, many cards: every independent line gets its own thread (with its own link,
// resolved map and card client), so a slow or dead card delays nobody and one target
// failing never changes what happens on another.
#pragma once

#include <functional>
#include <vector>

#include "ops/apply_run.hpp"

namespace i20::ops {

// Told each target's activity ("connecting", "writing NVBRAKEONV (2/5)", the outcome at
// the end), from the worker threads: it must be thread-safe.
using FleetActivity = std::function<void(std::size_t index, const std::string& what)>;

// Runs in the order given within a serial line or simulator (targets sharing a line_key),
// concurrently across lines; the channels of one Ethernet SSERIAL port run side by side,
// their commands sharing SSLBP DOITs. Returns one run per target, in the order of `targets`.
std::vector<TargetRun> run_fleet(const std::vector<Endpoint>& targets, const ApplyJob& job,
                                 const FleetActivity& activity = {});

// The fleet's scheduling for any per-card work (apply, validate, diff): `task(i, open)` is
// called once per target, in the threads described above; `open()` opens that target's card
// (or throws the error that kept its line or Ethernet port from opening). `task` must not
// throw.
using FleetTask = std::function<void(std::size_t index, const AmpOpener& open)>;
void for_each_target(const std::vector<Endpoint>& targets, const params::ParamDb& db, const OpenOptions& open,
                     const Cancel& cancel, const FleetTask& task);

}  // namespace i20::ops
