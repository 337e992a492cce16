// i20 discover: placeholder registration until the discovery module lands.
#include <CLI/CLI.hpp>

#include "context.hpp"

namespace i20::cli {

void register_discover_command(CLI::App&, Context&) {}

}  // namespace i20::cli
