// SPDX-License-Identifier: GPL-2.0-or-later
// `watch --passive`, `faults --passive` and `scan --passive`: the views of lib/ops'
// passive monitor beside a running machine. Only flag checks and rendering live here.
#pragma once

#include <cstdint>
#include <string>

#include "context.hpp"
#include "ops/core/timing.hpp"

namespace i20::cli {

struct PassiveWatchOptions {
  unsigned interval_ms = static_cast<unsigned>(ops::timing::kWatchInterval.count());
  std::uint64_t count = 0;  // 0: no limit
  double duration_s = 0;    // 0: no limit
  double busv_step_v = 0.5;
  std::string log;  // CSV file, one row per 8I20 per sample
};

// The --help text shared by the three commands' --passive flags.
std::string passive_flag_help(const std::string& what);

void run_passive_watch(Context& ctx, const PassiveWatchOptions& o);
void run_passive_faults(Context& ctx);
void run_passive_scan(Context& ctx);

// Appended to a running-host refusal: how to read without stopping anything.
std::string passive_hint(const Context& ctx);

}  // namespace i20::cli
