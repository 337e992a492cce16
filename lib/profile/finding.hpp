// SPDX-License-Identifier: GPL-2.0-or-later
// One result of checking a profile: an error stops an apply before anything is written, a
// warning is shown and the apply goes on.
#pragma once

#include <string>
#include <vector>

#include "error/error.hpp"

namespace i20::profile {

enum class Severity { Error, Warning };

struct Finding {
  Severity severity = Severity::Error;
  std::string key;      // the parameter (cell) or metadata key concerned, e.g. "NVBRAKEOFFV"
  std::string rule;     // stable rule id, e.g. "brake-order"; listed in profiles/README.md
  std::string message;  // one line, says what is wrong and why it matters
  std::string where;    // "file:line" of the entry, when the finding is about one
  // What overrides it (Advice::Force for an error that forcing turns into a warning): the
  // message names no command-line option, the app that shows it adds its own.
  Advice advice = Advice::None;
};

const char* to_string(Severity severity);
bool has_errors(const std::vector<Finding>& findings);

}  // namespace i20::profile
