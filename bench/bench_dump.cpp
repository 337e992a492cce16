// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 4's figures: `i20 dump` against the simulator with wire-time emulation at 115200
// baud and 1 ms turnaround per reply burst, against the wire-time bound for the same
// bytes, and against reading the same parameters with one `rpd` process each.
//
// Everything here is measured against i20sim (a pseudo-terminal with emulated wire
// time), not a real 8I20 behind a real USB adapter.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "build_paths.hpp"
#include "device/amp.hpp"
#include "link/serial_link.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/retry.hpp"
#include "ops/core/timing.hpp"
#include "sim_process.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace i20;

constexpr double kBaud = 115200.0;
constexpr int kTurnaroundUs = 1000;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

namespace {

int bench_main(int argc, char** argv) {
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 15;
  const std::string turnaround = std::to_string(kTurnaroundUs);
  bench::SimProcess sim({"--pty", "--wire-time", "--turnaround-us", turnaround});
  const std::string bin = i20::test::bin_dir().string();
  auto db = params::ParamDb::builtin();
  std::vector<const params::Param*> all;
  for (const auto& p : db.all())
    if (p.address) all.push_back(&p);

  // In-process: the same reads `i20 dump` does (one pipelined pass that also identifies
  // the card).
  std::vector<double> in_process;
  link::LinkStatistics stats;
  for (int i = 0; i < runs; ++i) {
    auto link =
        link::open_serial_link(sim.address(), ops::timing::serial_link({}, {}), ops::timing::serial_port({}));
    auto fresh_db = db;  // not identified yet, as in a new i20 process
    device::Amp8i20 amp(*link, fresh_db, ops::timing::amp());
    const auto t0 = Clock::now();
    amp.read(all);
    in_process.push_back(ms_since(t0));
    stats = link->statistics();
  }

  std::vector<double> dump_process;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = Clock::now();
    if (bench::run_quiet({bin + "/i20", "--port", sim.address(), "--no-user-params", "dump"}) != 0)
      throw std::runtime_error("i20 dump failed");
    dump_process.push_back(ms_since(t0));
  }

  std::vector<double> rpd_total;
  for (int i = 0; i < std::max(1, runs / 5); ++i) {
    const auto t0 = Clock::now();
    for (const auto* p : all)
      if (bench::run_quiet({bin + "/rpd", "--port", sim.address(), "--no-user-params", p->name}) != 0)
        throw std::runtime_error("rpd " + p->name + " failed");
    rpd_total.push_back(ms_since(t0));
  }

  const double byte_ms = 10.0 / kBaud * 1000.0;  // 8N1: 10 bit times per byte
  const double serial_bound = (stats.bytes_sent + stats.bytes_received) * byte_ms;
  const double duplex_bound = std::max(stats.bytes_sent, stats.bytes_received) * byte_ms;
  const double dump_in = median(in_process), dump_proc = median(dump_process), rpd = median(rpd_total);

  std::printf("i20 dump benchmark against i20sim (simulated: 115200 baud wire time, %d us turnaround)\n",
              kTurnaroundUs);
  std::printf("  parameters read            %zu\n", all.size());
  std::printf("  bytes on the wire          %llu sent, %llu received, %llu exchanges, %llu bursts\n",
              static_cast<unsigned long long>(stats.bytes_sent),
              static_cast<unsigned long long>(stats.bytes_received),
              static_cast<unsigned long long>(stats.exchanges),
              static_cast<unsigned long long>(stats.bursts));
  std::printf("  wire bound, one way at a time  %7.2f ms  (sent + received bytes x 10 bits / 115200)\n",
              serial_bound);
  std::printf("  wire bound, full duplex        %7.2f ms  (the longer direction alone)\n", duplex_bound);
  std::printf("  dump, in-process (median of %d) %7.2f ms  = %.2fx one-way bound, %.2fx full-duplex bound\n",
              runs, dump_in, dump_in / serial_bound, dump_in / duplex_bound);
  std::printf("  i20 dump process (median of %d) %7.2f ms  = %.2fx one-way bound\n", runs, dump_proc,
              dump_proc / serial_bound);
  std::printf("  one rpd process per parameter  %7.2f ms  = %.1fx the i20 dump process\n", rpd,
              rpd / dump_proc);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return i20::bench::run_main([&] { return bench_main(argc, argv); });
}
