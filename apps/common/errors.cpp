// SPDX-License-Identifier: GPL-2.0-or-later
#include "errors.hpp"

#include <yaml-cpp/exceptions.h>

#include <iostream>

#include "lbp/error.hpp"

namespace i20::app {
namespace {

int print(const char* program, const std::string& label, const std::string& message, int code) {
  std::cerr << program << ": " << label << ": " << message << "\n";
  return code;
}

}  // namespace

int report_current_exception(const char* program) {
  try {
    throw;
  } catch (const Error& e) {
    return print(program, ops::error_label(e.kind()), e.what(), ops::exit_code(e.kind()));
  } catch (const YAML::Exception& e) {
    return print(program, "error", std::string("YAML: ") + e.what(), kBadInput);
  } catch (const std::exception& e) {
    // Not one of the toolkit's own errors: a defect, at a point nobody planned for, so
    // nothing can be claimed about the card. Say so rather than guess.
    return print(program, "internal error",
                 std::string(e.what()) +
                     " (a defect: please report it; the card's "
                     "state is not known, check it with `i20 dump`)",
                 kCardState);
  }
}

}  // namespace i20::app
