// SPDX-License-Identifier: GPL-2.0-or-later
// The one-line answer to a command-line mistake, shared by every program (i20, wpd, rpd and
// i20sim, which links nothing else of the apps' common code).
#pragma once

namespace CLI {
class App;
class ParseError;
}  // namespace CLI

namespace i20::app {

// A command-line mistake CLI11 found, as one line: "PROGRAM: error: WHAT (`PROGRAM --help`
// explains the options)", exit 2. --help and --version print their text and return 0.
int report_parse_error(const CLI::App& app, const CLI::ParseError& e, const char* program);

}  // namespace i20::app
