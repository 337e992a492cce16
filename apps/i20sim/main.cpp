// SPDX-License-Identifier: GPL-2.0-or-later
// i20sim: the virtual 8I20 as a serial port. See `i20sim --help`.
#include <algorithm>
#include <cstdio>
#include <iostream>

#include "cli.hpp"
#include "error/error.hpp"
#include "lbp/rpc.hpp"
#include "params/text.hpp"
#include "sim/control.hpp"
#include "sim/rpc_table.hpp"
#include "sim/virtual_8i20.hpp"

namespace {

using namespace i20;

void print_map(const sim::RegisterMap& map) {
  std::printf("SWREVISION 0x%04X\n", map.swrevision());
  auto regs = map.all();
  std::sort(regs.begin(), regs.end(), [](const auto& a, const auto& b) {
    return std::tie(a.space, a.address) < std::tie(b.space, b.address);
  });
  for (const auto& r : regs)
    std::printf("%-6s 0x%04X %-15s %2u bit%s%s\n", r.space == sim::Space::Ram ? "ram" : "eeprom", r.address,
                r.name.c_str(), r.width_bits, r.is_signed ? " signed" : "", r.read_only ? " ro" : "");
  const auto table = sim::preloaded_rpc_table(map);
  for (unsigned n = 0; n < 4; ++n) {
    std::printf("RPC %u:", n);
    for (const auto& step : lbp::decode_rpc_list(table, n).steps)
      std::printf(" %s %zu @0x%04X", step.header.write ? "write" : "read", step.header.data_bytes(),
                  step.address.value_or(0));
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  sim::app::Invocation inv;
  if (auto code = sim::app::parse_command_line(argc, argv, inv)) return *code;
  try {
    if (inv.print_map) {
      print_map(inv.sim.device.map);
      return 0;
    }
    if (inv.eth) {
      inv.eth_options.read_stdin = inv.server.read_stdin;
      inv.eth_options.control_fifo = inv.server.control_fifo;
      return sim::app::serve_eth(inv.sim, inv.eth_options, inv.startup_control);
    }
    sim::Virtual8i20 card(inv.sim.device, sim::Clock::now());
    for (const auto& line : inv.startup_control) sim::apply_control(card, line, sim::Clock::now());
    if (inv.trace)
      card.set_trace([](const std::string& line) { std::cerr << "i20sim: " << line << std::endl; });
    return sim::app::serve(card, inv.sim.wire, inv.server);
  } catch (const Error& e) {
    std::cerr << "i20sim: " << params::printable(e.what()) << std::endl;
    return 1;
  }
}
