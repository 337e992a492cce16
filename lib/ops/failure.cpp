// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/failure.hpp"

#include <yaml-cpp/exceptions.h>

#include "eth/running_host.hpp"

namespace i20::ops {

Failure failure_of_current_exception() {
  try {
    throw;
  } catch (const eth::RunningHostError& e) {
    return {outcome_of(e.kind()), {error_label(e.kind()), e.what()}, Advice::RunningHost};
  } catch (const Error& e) {
    return {outcome_of(e.kind()), {error_label(e.kind()), e.what()}};
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
