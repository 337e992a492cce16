// Registration point; the subcommands land with their issue.
#include <CLI/CLI.hpp>

#include "context.hpp"

namespace i20::cli {

void register_fault_commands(CLI::App&, Context&) {}

}  // namespace i20::cli
