// i20: the umbrella CLI for Mesa 8I20 servo amplifiers.
#include <CLI/CLI.hpp>
#include <iostream>

#include "context.hpp"
#include "interrupt.hpp"
#include "version/build_info.hpp"

using namespace i20;

int main(int argc, char** argv) {
  CLI::App app{
      "i20: set up Mesa 8I20 servo amplifiers: read and write parameters by name, decode and clear\n"
      "faults, apply motor profiles. Talks to the card over a serial RS-422 adapter (3I21/3I22, jumper\n"
      "W6 down = setup mode, 115200 baud), over Ethernet through a 7I96S/7I92T, or to the built-in\n"
      "simulator (--sim), which is the way to try everything without hardware.\n\n"
      "Try:  i20 --sim info   |   i20 --sim dump   |   i20 --sim set NVBRAKEONV=320V"};
  app.set_version_flag("--version", "i20 " + std::string(build::kVersion), "Print the version and exit");
  app.require_subcommand(1);
  app.fallthrough();  // global options may follow the subcommand
  cli::Context ctx;
  app::add_target_options(app, ctx.options);
  app::add_database_options(app, ctx.options);
  app.add_flag("--json", ctx.options.json, "Machine-readable JSON output");
  cli::register_param_commands(app, ctx);
  cli::register_discover_command(app, ctx);
  cli::register_fault_commands(app, ctx);
  cli::register_profile_commands(app, ctx);
  cli::register_scan_command(app, ctx);

  app::install_interrupt_handler();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? app::kOk : app::kBadInput;
  } catch (...) {
    ctx.print_notes();
    return app::report_current_exception("i20");
  }
  ctx.print_notes();
  return ctx.exit_code;
}
