// SPDX-License-Identifier: GPL-2.0-or-later
// What a failure means, in one place for every program and use case: the toolkit's own
// errors by their kind, YAML errors as bad input, and anything else as a defect after which
// nothing is claimed about the card.
#pragma once

#include <string>

#include "error/error.hpp"
#include "ops/core/outcome.hpp"

namespace i20::ops {

// One line a program says about a failure: "LABEL: MESSAGE" ("error", "refused", "card
// state", "note", ...). Not faults::ReportLine, which is one bit of a fault report.
struct MessageLine {
  std::string label;
  std::string message;
};

// What the apps may add to a failure's message: the flag that changes it is theirs to name
// (RunningHost: the take-over option, and a passive read where the app has one; Force;
// AllowUnverified). Defined below every layer (error/error.hpp), since errors, profile
// findings and transaction results all carry it.
using Advice = i20::Advice;

// What a failure means, for the exception being handled (call from a catch block): the
// toolkit's own errors by their kind; YAML errors are bad input; anything else is a defect
// at a point nobody planned for, so nothing is claimed about the card (uncertain).
struct Failure {
  Outcome outcome = Outcome::Uncertain;
  MessageLine line;
  Advice advice = Advice::None;
};
Failure failure_of_current_exception();

}  // namespace i20::ops
