// rpd: read one 8I20 parameter by name, a drop-in for Mesa's RPD.
//   rpd BUSV        -> 32000      (10 mV units: 320 V)
//   rpd FAULT H     -> 0102       (hexadecimal word)
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "errors.hpp"
#include "legacy_env.hpp"
#include "params/value.hpp"
#include "session.hpp"
#include "version/build_info.hpp"

using namespace i20;

int main(int argc, char** argv) {
  CLI::App cli{
      "rpd: read an 8I20 parameter by its symbolic name (drop-in for Mesa's RPD).\n"
      "Prints the raw value in decimal, or in hexadecimal when H follows the name.\n"
      "The port comes from COMPORT (and BAUDRATE, PROTOCOL=LBP) like RPD, or --port.\n"
      "Examples:\n  COMPORT=/dev/ttyUSB0 rpd BUSV\n  rpd --sim FAULT H"};
  cli.set_version_flag("--version", "rpd " + std::string(build::kVersion), "Print the version and exit");
  app::GlobalOptions options;
  std::string name, hex;
  cli.add_option("NAME", name, "Parameter name, e.g. BUSV, NVMAXCURRENT, FAULT")->required();
  cli.add_option("H", hex, "H to print hexadecimal")->check(CLI::IsMember({"H", "h"}));
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
    const auto value = session.amp().read(param.name);
    if (!value.address_confirmed)
      std::cerr << "rpd: warning: the address of " << param.name
                << " is not confirmed for this 8I20's firmware; the value may belong to another parameter\n";
    if (hex.empty()) {
      std::cout << value.raw << "\n";
    } else {
      const auto mask = param.width_bits == 32 ? 0xFFFFFFFFull : (1ull << param.width_bits) - 1;
      std::printf("%0*llX\n", static_cast<int>(param.width_bits / 4),
                  static_cast<unsigned long long>(value.raw) & mask);
    }
    return app::kOk;
  } catch (...) {
    return app::report_current_exception("rpd");
  }
}
