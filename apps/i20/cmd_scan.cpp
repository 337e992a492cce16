// SPDX-License-Identifier: GPL-2.0-or-later
// i20 scan --eth IP: the card, its SSERIAL ports and channels, and which 8I20s answer,
// with the eth:// target and the LinuxCNC hostmot2 name of each. Refused while another
// host runs the card, unless --take-over (the global option every Ethernet command takes;
// `scan --force` is its deprecated, hidden spelling).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <memory>

#include "context.hpp"
#include "lbp/bytes.hpp"
#include "ops/scan.hpp"
#include "passive.hpp"

namespace i20::cli {
namespace {

app::Json scan_json(const ops::ScanResult& r) {
  auto j = app::Json::object();
  j.set("address", r.card_address.describe()).set("card", r.card.card_name);
  j.set("lbp16_version", r.card.lbp16_version).set("firmware_version", r.card.firmware_version);
  j.set("config", r.config_name).set("board", r.board_name);
  auto ports = app::Json::array();
  for (const auto& p : r.ports) {
    auto pj = app::Json::object();
    pj.set("port", p.index)
        .set("sslbp_version", p.parameters.version())
        .set("channels", p.parameters.channels);
    auto chans = app::Json::array();
    for (const auto& c : p.channels) {
      auto cj = app::Json::object();
      cj.set("channel", c.channel).set("answered", c.answered).set("device", c.device_name);
      cj.set("unit_number", c.unit_number).set("status", c.status).set("is_8i20", c.is_8i20());
      if (c.is_8i20()) {
        cj.set("target", ops::EthTarget{r.card_address, p.index, c.channel}.url());
        cj.set("linuxcnc_name", c.linuxcnc_name);
      }
      chans.push(std::move(cj));
    }
    pj.set("channel_reports", std::move(chans));
    ports.push(std::move(pj));
  }
  j.set("ports", std::move(ports));
  j.set("other_host", r.host_activity.describe());
  j.set("foreign_packets_during_scan", r.foreign_packets_during_scan);
  return j;
}

void print_scan(const ops::ScanResult& r) {
  std::cout << r.card.card_name << " at " << r.card_address.describe() << ": LBP16 version "
            << r.card.lbp16_version << ", firmware " << r.card.firmware_version << ", " << r.config_name
            << " board " << r.board_name << "\n";
  if (r.ports.empty())
    std::cout << "  no SSERIAL port in this configuration (load a bitfile with SSERIAL/SSLBP)\n";
  for (const auto& p : r.ports) {
    std::cout << "  SSERIAL port " << p.index << ": SSLBP " << p.parameters.version() << ", "
              << int(p.parameters.channels) << " channel(s)\n";
    for (const auto& c : p.channels) {
      std::cout << "    ch " << c.channel << ": ";
      if (c.is_8i20())
        std::cout << "8I20 unit " << c.unit_number << " (" << lbp::hex_value(c.unit_number, 8) << ")  -> "
                  << ops::EthTarget{r.card_address, p.index, c.channel}.url() << "  LinuxCNC "
                  << c.linuxcnc_name << "\n";
      else if (c.answered)
        std::cout << c.device_name << " (not an 8I20), unit " << c.unit_number << "\n";
      else
        std::cout << "nothing answers (" << c.status << ")\n";
    }
  }
  const auto targets = r.targets();
  std::cout << targets.size() << " 8I20(s) found; use a target above with --port, e.g. i20 --port "
            << (targets.empty() ? "eth://IP/ch0" : targets.front().url()) << " info\n";
}

void run_scan(Context& ctx, bool deprecated_force) {
  if (deprecated_force)
    std::cerr << "i20: `scan --force` is deprecated: it is the global --take-over (i20 --take-over scan "
                 "--eth IP)\n";
  // Not the session's target: scan names the card itself (an 8I20's channel is not needed).
  if (ctx.options.target.eth.empty())
    throw UsageError("scan needs the Ethernet card's address: i20 scan --eth 192.168.1.121");
  auto link = ctx.options.link;
  link.take_over = link.take_over || deprecated_force;
  const auto run = ops::scan_host_port(*ops::ethernet_host_port(ctx.options.target), link);
  const auto& result = run.result;
  if (run.stopped_running_host)
    std::cerr << "i20: scan --take-over: " << result.host_activity.describe()
              << "; the SSERIAL ports were stopped under that host, its axes dropped out\n";
  if (result.foreign_packets_during_scan > 0)
    std::cerr << "i20: another host sent " << result.foreign_packets_during_scan
              << " packet(s) to the card during the scan: its DOITs may have changed what the channels "
                 "reported; stop it and scan again\n";
  if (ctx.options.json)
    ctx.print_json(scan_json(result));
  else
    print_scan(result);
}

}  // namespace

void register_scan_command(CLI::App& app, Context& ctx) {
  auto* scan = app.add_subcommand(
      "scan",
      "Scan a 7I96S/7I92T over Ethernet (--eth IP): the card, its SSERIAL ports and channels, which 8I20s "
      "answer (name, unit number), their eth:// targets and LinuxCNC hostmot2 names. Scanning stops and "
      "restarts every smart-serial port, so it first watches the card for 45 ms and refuses while another "
      "host (LinuxCNC) is running it, unless the global --take-over is given (then its smart-serial ports "
      "stop, every 8I20 on them sees no DOIT for 40 ms and disables its output, and LinuxCNC drops every "
      "axis on those ports with a watchdog fault)");
  auto force = std::make_shared<bool>(false);
  // The old spelling of --take-over, kept (hidden) so scripts keep working.
  scan->add_flag("--force", *force, "Deprecated: the global --take-over")->group("");
  auto passive = std::make_shared<bool>(false);
  scan->add_flag(
      "--passive", *passive,
      passive_flag_help("the 8I20s the running host has on each channel, with their bus voltage and FAULT,") +
          "; unit numbers need a setup start and are not shown");
  scan->callback([&ctx, force, passive] {
    if (*passive)
      run_passive_scan(ctx);
    else
      run_scan(ctx, *force);
  });
}

}  // namespace i20::cli
