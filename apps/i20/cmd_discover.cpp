// SPDX-License-Identifier: GPL-2.0-or-later
// i20 discover: find the working (RAM) addresses of the connected card, read-only.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iomanip>
#include <iostream>

#include "context.hpp"
#include "lbp/bytes.hpp"
#include "ops/discover.hpp"
#include "ops/core/errors.hpp"
#include "output_file.hpp"

namespace i20::cli {
namespace {

struct DiscoverOptions {
  std::string out;
  std::string range = "0x0800-0x27FF";
  bool no_reset = false;
  bool yes = false;
  bool overwrite = false;
};

std::pair<std::uint16_t, std::uint32_t> parse_range(const std::string& text) {
  const auto dash = text.find('-');
  try {
    if (dash == std::string::npos) throw std::invalid_argument(text);
    const auto begin = std::stoul(text.substr(0, dash), nullptr, 0);
    const auto last = std::stoul(text.substr(dash + 1), nullptr, 0);
    if (begin > last || last > 0xFFFF) throw std::out_of_range(text);
    return {static_cast<std::uint16_t>(begin), static_cast<std::uint32_t>(last + 1)};
  } catch (const std::exception&) {
    throw UsageError("--range '" + text + "' must be FIRST-LAST within 0x0000-0xFFFF, e.g. 0x0800-0x27FF");
  }
}

std::string now_text() {
  const auto t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M", std::localtime(&t));
  return buf;
}

void print_report(const ops::DiscoveryReport& r) {
  std::cout << std::left << std::setw(14) << "PARAMETER" << std::setw(16) << "RESULT" << std::setw(9)
            << "ADDRESS" << std::setw(10) << "DATABASE"
            << "HOW\n";
  for (const auto& f : r.findings) {
    std::cout << std::left << std::setw(14) << f.name << std::setw(16) << ops::to_string(f.outcome)
              << std::setw(9) << (f.address ? lbp::hex_value(*f.address, 4) : "-") << std::setw(10)
              << (f.database_address ? lbp::hex_value(*f.database_address, 4) : "-") << f.detail << "\n";
  }
  std::cout << r.count(ops::Search::Found) << " found, " << r.count(ops::Search::Ambiguous) << " ambiguous, "
            << r.count(ops::Search::NotFound) << " not found, " << r.count(ops::Search::NotSearchable)
            << " not searchable read-only\n";
}

app::Json report_json(const ops::DiscoveryReport& r, const std::string& file) {
  auto j = app::Json::object();
  j.set("swrevision", r.swrevision).set("unit_number", r.unit_number).set("was_reset", r.was_reset);
  j.set("overlay_file", file);
  auto arr = app::Json::array();
  for (const auto& f : r.findings) {
    auto e = app::Json::object();
    e.set("name", f.name).set("outcome", ops::to_string(f.outcome));
    e.set("address", f.address ? app::Json(*f.address) : app::Json());
    auto c = app::Json::array();
    for (auto a : f.candidates) c.push(a);
    e.set("candidates", std::move(c)).set("detail", f.detail);
    arr.push(std::move(e));
  }
  j.set("findings", std::move(arr));
  return j;
}

void run_discover(Context& ctx, const DiscoverOptions& o) {
  ops::DiscoverOptions options;
  std::tie(options.scan.scan_begin, options.scan.scan_end) = parse_range(o.range);
  options.scan.reset_first = !o.no_reset;
  options.output = o.out;
  options.overwrite = o.overwrite;
  options.generated_at = now_text();
  check_output_file(o.out, o.overwrite);  // before the first byte: no reset, no scan for a refusal
  if (options.scan.reset_first && !o.yes)
    ctx.require_confirmation(
        "Discovery resets the 8I20 on " + ctx.session().endpoint().text +
            " (so working values equal NV values), then only reads. Go on?",
        "discover not confirmed; nothing was sent (pass --yes, or --no-reset right after a "
        "power-up)");
  auto& amp = ctx.amp();
  if (isatty(STDERR_FILENO))
    options.scan.progress = [](std::size_t done, std::size_t total) {
      std::cerr << "\rscanning RAM: " << (100 * done / total) << "%" << (done == total ? "\n" : "")
                << std::flush;
    };
  const auto result = ops::discover(amp, ctx.session().db(), options);
  const std::string file = result.written.string();
  if (ctx.options.json) {
    ctx.print_json(report_json(result.report, file));
    return;
  }
  print_report(result.report);
  std::cout << "overlay written to " << file << " (loaded back and accepted): use it with `i20 "
            << ctx.target_flags() << " --params " << file
            << " ...` or copy it to ~/.config/i20/params.yaml\n";
}

}  // namespace

void register_discover_command(CLI::App& app, Context& ctx) {
  auto o = std::make_shared<DiscoverOptions>();
  auto* cmd = app.add_subcommand("discover",
                                 "Find the working-parameter (RAM) addresses of this card without writing "
                                 "parameters: decode the pre-loaded "
                                 "RPC table, reset, scan RAM read-only for each NV value. Writes an overlay "
                                 "file saying what was found and how");
  cmd->add_option("--out,-o", o->out, "Overlay file to write (default: i20-map-SWREVISION.yaml)");
  cmd->add_option("--range", o->range,
                  "RAM range to scan, FIRST-LAST (default 0x0800-0x27FF, above a DSP's special-function "
                  "registers whose reads may have side effects)");
  cmd->add_flag("--no-reset", o->no_reset,
                "Do not reset first (only right after a power-up with no changes)");
  cmd->add_flag("--yes,-y", o->yes, "Do not ask before the reset");
  cmd->add_flag("--overwrite", o->overwrite, "Replace the overlay file if it exists");
  cmd->callback([&ctx, o] { run_discover(ctx, *o); });
}

}  // namespace i20::cli
