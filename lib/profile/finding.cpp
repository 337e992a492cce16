// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/finding.hpp"

#include <algorithm>

namespace i20::profile {

const char* to_string(Severity severity) {
  return severity == Severity::Error ? "error" : "warning";
}

bool has_errors(const std::vector<Finding>& findings) {
  return std::ranges::any_of(findings, [](const Finding& f) { return f.severity == Severity::Error; });
}

}  // namespace i20::profile
