// wpd: write one 8I20 parameter by name, a drop-in for Mesa's WPD.
//   wpd NVMAXCURRENT 2500   -> EEPROM full-scale current 25 A (after a reset)
//   wpd BRAKEONV 30000      -> working brake-on voltage 300 V, live
//   wpd FAULT 0             -> clears faults (through CLEARFAULT, as the card requires)
#include <CLI/CLI.hpp>
#include <iostream>

#include "errors.hpp"
#include "legacy_env.hpp"
#include "params/value.hpp"
#include "session.hpp"
#include "version/build_info.hpp"

using namespace i20;

namespace {

int clear_faults(app::Session& session, const device::WriteOptions& write) {
  const auto result = session.amp().clear_faults(write);
  std::cout << "FAULT cleared through CLEARFAULT: was 0x" << std::hex << result.fault_before << ", now 0x"
            << result.fault_after << std::dec << "\n";
  if (result.fault_after != 0) {
    std::cerr << "wpd: faults remain because their cause is still present; run `i20 faults` for details\n";
    return app::kFaultsRemain;
  }
  return app::kOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{
      "wpd: write an 8I20 parameter by its symbolic name (drop-in for Mesa's WPD).\n"
      "VALUE is a raw integer in the parameter's units (10 mV, 10 mA, ...), decimal or 0x hex.\n"
      "NV (EEPROM) parameters take effect after the 8I20 is reset. Values outside the\n"
      "database's range are refused before anything is sent.\n"
      "The port comes from COMPORT (and BAUDRATE, PROTOCOL=LBP) like WPD, or --port.\n"
      "Examples:\n  wpd NVMAXCURRENT 2500     (25 A)\n  wpd NVBRAKEONV 19000      (190 V)\n"
      "  wpd --sim BRAKEONV 30000  (300 V, live)"};
  cli.set_version_flag("--version", "wpd " + std::string(build::kVersion), "Print the version and exit");
  app::GlobalOptions options;
  device::WriteOptions write;
  std::string name, value_text;
  cli.add_option("NAME", name, "Parameter name, e.g. NVMAXCURRENT")->required();
  cli.add_option("VALUE", value_text, "Raw integer value")->required();
  cli.add_flag("--allow-unverified", write.allow_unverified,
               "Write a working (RAM) address the database does not confirm for this firmware");
  cli.add_flag("--force", write.force, "Write a guarded parameter (NVBAUDRATE, setpoints); read why first");
  app::add_target_options(cli, options);
  app::add_database_options(cli, options);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli.exit(e) == 0 ? 0 : app::kBadInput;
  }
  try {
    app::apply_legacy_environment(options);
    app::Session session(options);
    const auto& param = session.db().get(name);
    const auto raw = params::parse_raw(param, value_text);
    // The manual's "WPD FAULT 0 would clear the FAULT parameter": FAULT itself is not
    // writable, the card clears faults through CLEARFAULT.
    if (param.name == "FAULT" && raw == 0) return clear_faults(session, write);
    device::check_offline(param, raw, write);  // before the link is even opened
    const auto report = session.amp().write(param.name, raw, write);
    std::cout << param.name << " = " << raw;
    if (!param.unit.empty()) std::cout << " (" << params::format_engineering(param, raw) << ")";
    std::cout << (report.verified ? " written and verified" : " written");
    if (report.needs_reset) std::cout << " in EEPROM; takes effect after the 8I20 is reset (i20 reset)";
    std::cout << "\n";
    return app::kOk;
  } catch (...) {
    return app::report_current_exception("wpd");
  }
}
