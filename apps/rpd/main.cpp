// SPDX-License-Identifier: GPL-2.0-or-later
// rpd: read one 8I20 parameter by name, a drop-in for Mesa's RPD.
//   rpd BUSV        -> 32000      (10 mV units: 320 V)
//   rpd FAULT H     -> 0102       (hexadecimal word)
//
// Only facts are printed: a working parameter whose address is not confirmed for the card's
// firmware is not read (exit 3) unless --allow-unverified asks for the raw word anyway.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>

#include "errors.hpp"
#include "ops/core/read.hpp"
#include "ops/core/signals.hpp"
#include "options.hpp"
#include "terminal.hpp"
#include "version/build_info.hpp"

using namespace i20;

static int run(int argc, char** argv) {
  CLI::App cli{
      "rpd: read an 8I20 parameter by its symbolic name (drop-in for Mesa's RPD).\n"
      "Prints the raw value in decimal, or in hexadecimal when H follows the name.\n"
      "The port comes from COMPORT (and BAUDRATE, PROTOCOL=LBP) like RPD, or --port.\n"
      "Exit status: 0 read, 1 card not reached, 2 bad input, 3 not read: the address is not\n"
      "confirmed for this card's firmware (run `i20 discover`), 6 output not written, 130 Ctrl-C.\n"
      "Examples:\n  COMPORT=/dev/ttyUSB0 rpd BUSV\n  rpd --sim FAULT H"};
  cli.set_version_flag("--version", "rpd " + std::string(build::kVersion), "Print the version and exit");
  app::GlobalOptions options;
  std::string name, hex;
  bool allow_unverified = false;
  cli.add_option("NAME", name, "Parameter name, e.g. BUSV, NVMAXCURRENT, FAULT")->required();
  cli.add_option("H", hex, "H to print hexadecimal")->check(CLI::IsMember({"H", "h"}));
  cli.add_flag("--allow-unverified", allow_unverified,
               "Read a working (RAM) address the database does not confirm for this firmware; the value may "
               "belong to another parameter");
  app::add_target_options(cli, options);
  app::add_database_options(cli, options);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app::report_parse_error(cli, e, "rpd");
  }
  app::set_overrides(app::overrides_of(cli));  // what its reports may name
  ops::install_stop_signals();  // SIGINT, SIGTERM, SIGHUP stop safely (ops::Session); SIGPIPE ignored
  options.legacy = ops::LegacyEnvironment::Required;
  try {
    ops::Session session(options, app::stop_acknowledgement("rpd"));
    try {
      const auto& param = session.db().get(name);  // unknown names fail before the link opens
      auto& amp = session.amp();
      const auto policy = allow_unverified ? ops::Unconfirmed::Read : ops::Unconfirmed::Skip;
      const auto reading = ops::read_values(amp, std::vector<std::string>{param.name}, policy).front();
      // An NV read the line cut short must not leave NV mode on unsaid.
      if (const auto settled = session.settle(); settled.outcome != ops::Outcome::Done)
        return ops::exit_code(settled.outcome);
      else if (settled.note)
        app::print_line("rpd", *settled.note);
      if (!reading.raw) {
        std::cerr << "rpd: refused: " << reading.param->name << " is " << ops::unknown_text(reading)
                  << "; run `i20 " << amp.endpoint().flags() << " discover`, or pass --allow-unverified\n";
        return ops::exit_code(ops::reading_outcome(std::span(&reading, 1)));
      }
      if (!reading.confirmed)
        std::cerr << "rpd: warning: " << reading.param->name << " read at an address " << reading.reason
                  << "; the value may belong to another parameter\n";
      const auto& p = *reading.param;
      if (hex.empty()) {
        std::cout << *reading.raw << "\n";
      } else {
        const auto mask = p.width_bits == 32 ? 0xFFFFFFFFull : (1ull << p.width_bits) - 1;
        std::printf("%0*llX\n", static_cast<int>(p.width_bits / 4),
                    static_cast<unsigned long long>(*reading.raw) & mask);
      }
      return ops::exit_code(ops::Outcome::Done);
    } catch (...) {
      return app::print_failure("rpd", session.fail());  // the card settled too: a mode may be on
    }
  } catch (...) {
    return app::report_current_exception("rpd");
  }
}

int main(int argc, char** argv) {
  // After the card is settled: a lost stdout changes nothing on it, but is not a success.
  return app::finish_output("rpd", run(argc, argv));
}
