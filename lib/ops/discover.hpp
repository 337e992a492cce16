// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 discover` as a use case: run the read-only discovery on an open card, then prove the
// overlay it produced loads (for that SWREVISION) before saying it was written, and prove it
// again from the file on disk.
#pragma once

#include <filesystem>
#include <string>

#include "device/discover.hpp"
#include "ops/core/amp.hpp"
#include "ops/core/timing.hpp"
#include "params/param_db.hpp"

namespace i20::ops {

// The device layer's discovery terms, as the apps name them (no app includes lib/device).
using device::DiscoveryReport;
using device::Search;
using device::to_string;

struct DiscoverOptions {
  // The range and whether to reset are the caller's; the wait after the reset is timing's.
  device::DiscoveryOptions scan{.reset_wait = timing::kResetWait};
  std::filesystem::path output;  // empty: i20-map-SWREVISION.yaml in the current directory
  bool overwrite = false;
  std::string generated_at;  // time stamp written into the file
};

struct DiscoverResult {
  device::DiscoveryReport report;
  std::filesystem::path written;  // the overlay file, loaded back and accepted
};

// Throws Cancelled on Ctrl-C (between scan chunks), UsageError when the file exists
// and `overwrite` is not set, ParamFileError when the overlay would not load (nothing is
// written then).
DiscoverResult discover(Amp& amp, const params::ParamDb& loaded, const DiscoverOptions& options);

}  // namespace i20::ops
