// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 hal lint --load`: runs the files in LinuxCNC's halrun against the virtual card
// (i20-halrun-virtual, with i20sim beside this program) and turns halcmd's complaints into
// findings on the files' lines. The plan and the reading are lib/linuxcnc/hal_load's.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "linuxcnc/hal_load.hpp"

namespace i20::cli {

struct HalLoadResult {
  std::vector<linuxcnc::LintFinding> findings;
  std::vector<std::string> left_out;  // "FILE:LINE: why"
  std::string ran;                    // "a virtual 7I96S at 10.10.10.10", for the summary
};

// `ini`: the configuration's INI file's text, for files that read INI values. Throws
// UsageError when it cannot run here (not root, no INI for files that read one) and Error
// when halrun failed without saying where.
HalLoadResult load_in_halrun(const std::vector<linuxcnc::HalSource>& sources,
                             const std::optional<std::string>& ini);

}  // namespace i20::cli
