// Issue 7's figure: UDP round trips per parameter read and write through a 7I96S's SSLBP
// setup-mode passthrough. Measured against `i20sim --eth` on loopback (a virtual 7I96S
// with a virtual 8I20), not a real card on a real network.

#include <chrono>
#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>

#include "device/amp.hpp"
#include "eth/passthrough_link.hpp"
#include "eth/target.hpp"
#include "sim_process.hpp"

namespace {

using namespace i20;
using Clock = std::chrono::steady_clock;

struct Cost {
  double packets;
  double ms;
};

// Average UDP packets and time per call of `op`.
Cost measure(eth::SslbpPassthroughLink& link, int runs, const std::function<void()>& op) {
  const auto before = link.transport_stats().packets_sent;
  const auto t0 = Clock::now();
  for (int i = 0; i < runs; ++i) op();
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  return {double(link.transport_stats().packets_sent - before) / runs, ms / runs};
}

}  // namespace

int main(int argc, char** argv) {
  const int runs = argc > 1 ? std::atoi(argv[1]) : 50;
  bench::SimProcess sim({"--eth", "127.0.0.1:0"});
  auto link = eth::SslbpPassthroughLink::open(eth::make_target(sim.address(), 0));
  auto db = params::ParamDb::builtin();
  device::Amp8i20 amp(*link, db);
  amp.identify();

  const Cost ram_read = measure(*link, runs, [&] { amp.read("BRAKEONV"); });
  const Cost nv_read = measure(*link, runs, [&] { amp.read("NVBRAKEONV"); });
  int flip = 0;
  const Cost ram_write = measure(*link, runs, [&] { amp.write("BRAKEONV", 30000 + (flip++ % 2), {}); });
  const Cost nv_write =
      measure(*link, std::max(1, runs / 5), [&] { amp.write("NVBRAKEONV", 30000 + (flip++ % 2), {}); });
  std::vector<const params::Param*> all;
  for (const auto& p : db.all())
    if (p.address) all.push_back(&p);
  const Cost dump = measure(*link, std::max(1, runs / 10), [&] { amp.read(all); });

  std::printf("Ethernet passthrough benchmark against i20sim --eth on loopback (simulated 7I96S + 8I20)\n");
  std::printf("  UDP round trips (request packets) per operation, and time per operation:\n");
  std::printf("  read a working parameter (1 LBP command)              %5.2f packets  %6.3f ms\n",
              ram_read.packets, ram_read.ms);
  std::printf("  read an NV parameter (NV mode on, read, check, off)   %5.2f packets  %6.3f ms\n",
              nv_read.packets, nv_read.ms);
  std::printf("  write+verify a working parameter (write, read back)   %5.2f packets  %6.3f ms\n",
              ram_write.packets, ram_write.ms);
  std::printf("  write+verify an NV parameter (6 LBP commands)         %5.2f packets  %6.3f ms\n",
              nv_write.packets, nv_write.ms);
  std::printf(
      "  dump, %zu parameters                                  %5.2f packets  %6.3f ms (%.2f packets per "
      "parameter)\n",
      all.size(), dump.packets, dump.ms, dump.packets / all.size());
  std::printf("  max round trips of any single LBP command so far: %llu\n",
              static_cast<unsigned long long>(link->stats().max_round_trips));
  return 0;
}
