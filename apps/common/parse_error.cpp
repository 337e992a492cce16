// SPDX-License-Identifier: GPL-2.0-or-later
#include "parse_error.hpp"

#include <CLI/CLI.hpp>
#include <iostream>

#include "ops/core/outcome.hpp"
#include "params/text.hpp"

namespace i20::app {

int report_parse_error(const CLI::App& app, const CLI::ParseError& e, const char* program) {
  if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
  std::cerr << program << ": error: " << params::printable(e.what()) << " (`" << program
            << " --help` explains the options)\n";
  return ops::kExitBadInput;
}

}  // namespace i20::app
