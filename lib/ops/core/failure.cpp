// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/failure.hpp"

#include <yaml-cpp/exceptions.h>

namespace i20::ops {

Failure failure_of_current_exception() {
  try {
    throw;
  } catch (const Error& e) {
    // What overrides it (a running host's take-over, a guard's force, ...) travels with it.
    return {outcome_of(e.kind()), {error_label(e.kind()), e.what()}, e.advice()};
  } catch (const YAML::Exception& e) {
    return {Outcome::BadInput, {"error", std::string("YAML: ") + e.what()}};
  } catch (const std::exception& e) {
    // Not one of the toolkit's own errors: a defect, at a point nobody planned for, so
    // nothing can be claimed about the card. Say so rather than guess.
    return {Outcome::Uncertain,
            {"internal error", std::string(e.what()) +
                                   " (a defect: please report it; the card's state is not known, check it "
                                   "with `i20 dump`)"}};
  }
}

}  // namespace i20::ops
