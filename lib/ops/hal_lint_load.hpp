// SPDX-License-Identifier: GPL-2.0-or-later
// The use case of `i20 hal lint --load`: runs the files in LinuxCNC's halrun against the
// virtual card (i20-halrun-virtual, with i20sim beside the program) and turns halcmd's
// complaints into findings on the files' lines. The plan and the reading are
// lib/linuxcnc/hal_load's; this owns the rest: the root check, the temporary folder the
// HAL user can read, running the rig and what its exit means.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "linuxcnc/hal_load.hpp"

namespace i20::ops {

struct HalLoadResult {
  std::vector<linuxcnc::LintFinding> findings;
  std::vector<std::string> left_out;  // "FILE:LINE: why"
  std::string ran;                    // "a virtual 7I96S at 10.10.10.10", for the summary
};

// `ini`: the configuration's INI file's text, for files that read INI values. `program`:
// the running program's own path (i20sim is beside it, the rig where it was installed).
// Throws UsageError when it cannot run here (not root, no INI for files that read one) and
// Error when halrun failed without saying where.
HalLoadResult load_in_halrun(const std::vector<linuxcnc::HalSource>& sources,
                             const std::optional<std::string>& ini, const std::filesystem::path& program);

}  // namespace i20::ops
