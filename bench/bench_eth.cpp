// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 12's figures: UDP request packets per operation through a 7I96S/7I92T's SSLBP
// setup-mode passthrough, one LBP command per packet (before batching) beside the
// batched link, and the serial time the DOITs take at the remote's baud. Measured against
// `i20sim --eth` on loopback (a virtual card with virtual 8I20s at 2.5 MBaud), not a real
// card on a real network: the packet counts carry over, the times do not.
//
// Targets: a 38-parameter dump of one 8I20 in at most 2 request packets, the same dump of
// 4 8I20s on one port in at most 3, an NV write with verify in at most 2.

#include <barrier>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "build_paths.hpp"
#include "device/amp.hpp"
#include "eth/passthrough_link.hpp"
#include "eth/running_host.hpp"
#include "eth/target.hpp"
#include "eth/udp_client.hpp"
#include "lbp/local.hpp"
#include "ops/core/endpoint.hpp"
#include "ops/core/retry.hpp"
#include "ops/core/timing.hpp"
#include "sim_process.hpp"

namespace {

using namespace i20;
using Clock = std::chrono::steady_clock;

// The passthrough as the programs open it (ops/core/timing.hpp): what the figures describe.
eth::PassthroughOptions passthrough_options() {
  return ops::timing::passthrough({}, {});
}

// Counts the execute() calls the device layer makes, so packets per execute() show.
class CountingLink final : public link::Link {
 public:
  explicit CountingLink(link::Link& inner) : inner_(inner) {}
  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override {
    ++executes;
    last.assign(batch.begin(), batch.end());
    return inner_.execute(batch);
  }
  std::string describe() const override { return inner_.describe(); }
  std::size_t max_data_bytes() const override { return inner_.max_data_bytes(); }
  unsigned executes = 0;
  std::vector<lbp::Command> last{};  // the last batch, as the device layer built it

 private:
  link::Link& inner_;
};

struct Cost {
  double packets = 0;
  double executes = 0;
  double ms = 0;
  double serial_us = 0;
};

// Average cost of `op` over `runs` calls.
Cost measure(eth::PassthroughPort& port, CountingLink& counting, int runs, const std::function<void()>& op) {
  const auto packets = port.transport_stats().packets_sent;
  const auto serial = port.stats().serial_time;
  const auto executes = counting.executes;
  const auto t0 = Clock::now();
  for (int i = 0; i < runs; ++i) op();
  Cost c;
  c.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count() / runs;
  c.packets = double(port.transport_stats().packets_sent - packets) / runs;
  c.executes = double(counting.executes - executes) / runs;
  c.serial_us = double((port.stats().serial_time - serial).count()) / runs;
  return c;
}

const char* verdict(double packets, double target) {
  return packets <= target ? "meets" : "MISSES";
}

std::vector<const params::Param*> dump_params(const params::ParamDb& db) {
  std::vector<const params::Param*> all;
  for (const auto& p : db.all())
    if (p.address) all.push_back(&p);
  return all;
}

// The built-in database resolved for the firmware the card behind `link` reports.
params::ParamDb resolved_db(link::Link& link) {
  auto loaded = params::ParamDb::builtin();
  const auto info = device::Amp8i20(link, loaded, ops::timing::amp()).info();
  if (!info.swrevision) throw std::runtime_error("the card reported no SWREVISION");
  return loaded.for_firmware(*info.swrevision);
}

struct OneAmp {
  Cost ram_read, nv_read, ram_write, nv_write, nv_write_one_batch, nv_write_two_batches, dump;
  std::size_t dump_size = 0;
  std::vector<lbp::Command> dump_batch{};  // what the device layer sends for the dump
  std::uint64_t late = 0;
};

// The whole NV write with its verify as one batch: what the device layer's three
// execute() calls (enter NV mode; mode check, write, read back, mode check; leave) would
// be as one.
void nv_write_one_batch(link::Link& link, const params::Param& p, std::uint16_t value) {
  namespace L = lbp::local;
  const auto size = *lbp::data_size_for(p.bytes());
  const auto mode = lbp::local_read(L::kGetNvAccess);
  const std::vector<lbp::Command> batch{lbp::set_nv_access(L::NvAccess::Eeprom),
                                        mode,
                                        lbp::write(*p.address, size, value),
                                        lbp::read(*p.address, size),
                                        mode,
                                        lbp::set_nv_access(L::NvAccess::Ram)};
  const auto r = link.execute(batch);
  if (r[1].at(0) != 1 || r[4].at(0) != 1 || lbp::read_le(r[3]) != value)
    throw std::runtime_error("the one-batch NV write did not verify");
}

// The same in two execute() calls: enter NV mode and check it; write, read back, check,
// leave, check (how the lead's lib/ops-era device layer sends one cell).
void nv_write_two_batches(link::Link& link, const params::Param& p, std::uint16_t value) {
  namespace L = lbp::local;
  const auto size = *lbp::data_size_for(p.bytes());
  const auto mode = lbp::local_read(L::kGetNvAccess);
  const std::vector<lbp::Command> enter{lbp::set_nv_access(L::NvAccess::Eeprom), mode};
  if (link.execute(enter)[1].at(0) != 1) throw std::runtime_error("not in NV mode");
  const std::vector<lbp::Command> cell{lbp::write(*p.address, size, value), lbp::read(*p.address, size), mode,
                                       lbp::set_nv_access(L::NvAccess::Ram), mode};
  const auto r = link.execute(cell);
  if (lbp::read_le(r[1]) != value || r[2].at(0) != 1 || r[4].at(0) != 0)
    throw std::runtime_error("the two-batch NV write did not verify");
}

OneAmp one_amp(const std::string& address, unsigned doits_per_packet, int runs) {
  auto options = passthrough_options();
  options.max_doits_per_packet = doits_per_packet;
  auto link = eth::SslbpPassthroughLink::open(eth::make_target(address, 0), options);
  CountingLink counting(*link);
  // Resolved for the card's firmware, as a session does: the working addresses are
  // confirmed only for the revision the simulator reports, and the benchmark writes only
  // confirmed addresses (no --allow-unverified).
  const auto db = resolved_db(counting);
  device::Amp8i20 amp(counting, db, ops::timing::amp());
  amp.identify();
  auto& port = link->port();
  OneAmp r;
  int flip = 0;
  r.ram_read = measure(port, counting, runs, [&] { amp.read("BRAKEONV"); });
  r.nv_read = measure(port, counting, runs, [&] { amp.read("NVBRAKEONV"); });
  r.ram_write = measure(port, counting, runs, [&] { amp.write("BRAKEONV", 30000 + (flip++ % 2), {}); });
  const int nv_runs = std::max(1, runs / 5);  // EEPROM cells wear; the simulator's too, in spirit
  r.nv_write = measure(port, counting, nv_runs, [&] { amp.write("NVBRAKEONV", 30000 + (flip++ % 2), {}); });
  const auto& nvbrakeon = db.get("NVBRAKEONV");
  r.nv_write_one_batch = measure(port, counting, nv_runs, [&] {
    nv_write_one_batch(counting, nvbrakeon, static_cast<std::uint16_t>(30000 + (flip++ % 2)));
  });
  r.nv_write_two_batches = measure(port, counting, nv_runs, [&] {
    nv_write_two_batches(counting, nvbrakeon, static_cast<std::uint16_t>(30000 + (flip++ % 2)));
  });
  const auto all = dump_params(db);
  r.dump_size = all.size();
  r.dump = measure(port, counting, std::max(1, runs / 10), [&] { amp.read(all); });
  r.dump_batch = counting.last;
  r.late = port.stats().late_doits;
  return r;
}

// The dump of every 8I20 on the port: one thread per 8I20 (as a fleet runs), each with its
// own link to the shared port, all starting together.
Cost four_amps_shared(const std::string& address, unsigned amps, int runs) {
  auto port = eth::PassthroughPort::open(eth::parse_host_port(address), 0,
                                         static_cast<std::uint8_t>((1u << amps) - 1), passthrough_options());
  std::vector<std::unique_ptr<link::Link>> links;
  std::vector<params::ParamDb> dbs;
  for (unsigned ch = 0; ch < amps; ++ch) {
    links.push_back(port->link(ch));
    dbs.push_back(params::ParamDb::builtin());
  }
  std::barrier start(static_cast<std::ptrdiff_t>(amps + 1));
  std::vector<std::thread> threads;
  for (unsigned ch = 0; ch < amps; ++ch)
    threads.emplace_back([&, ch] {
      device::Amp8i20 amp(*links[ch], dbs[ch], ops::timing::amp());
      const auto all = dump_params(dbs[ch]);
      amp.identify();
      start.arrive_and_wait();  // identified: the port is idle
      for (int i = 0; i < runs; ++i) {
        start.arrive_and_wait();
        amp.read(all);
        start.arrive_and_wait();
      }
    });
  Cost c;
  start.arrive_and_wait();
  for (int i = 0; i < runs; ++i) {
    const auto packets = port->transport_stats().packets_sent;  // every thread waits: the port is idle
    const auto serial = port->stats().serial_time;
    const auto t0 = Clock::now();
    start.arrive_and_wait();  // go
    start.arrive_and_wait();  // every dump done
    c.ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    c.packets += double(port->transport_stats().packets_sent - packets);
    c.serial_us += double((port->stats().serial_time - serial).count());
  }
  for (auto& t : threads) t.join();
  c.ms /= runs;
  c.packets /= runs;
  c.serial_us /= runs;
  return c;
}

// The device layer's dump batch on every channel at once through PassthroughPort::execute:
// the packing alone, without the threads' timing.
Cost four_amps_one_execute(const std::string& address, unsigned amps, const std::vector<lbp::Command>& batch,
                           int runs) {
  auto port = eth::PassthroughPort::open(eth::parse_host_port(address), 0,
                                         static_cast<std::uint8_t>((1u << amps) - 1), passthrough_options());
  std::vector<eth::PassthroughPort::Batch> batches;
  for (unsigned ch = 0; ch < amps; ++ch) batches.push_back({.channel = ch, .commands = batch});
  Cost c;
  for (int i = 0; i < runs; ++i) {
    const auto packets = port->transport_stats().packets_sent;
    const auto serial = port->stats().serial_time;
    const auto t0 = Clock::now();
    for (const auto& o : port->execute(batches))
      if (o.error) std::rethrow_exception(o.error);
    c.ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    c.packets += double(port->transport_stats().packets_sent - packets);
    c.serial_us += double((port->stats().serial_time - serial).count());
  }
  c.ms /= runs;
  c.packets /= runs;
  c.serial_us /= runs;
  return c;
}

// Before batching: one link per 8I20, opened one after the other, one command per packet.
Cost four_amps_one_by_one(const std::string& address, unsigned amps) {
  Cost total;
  for (unsigned ch = 0; ch < amps; ++ch) {
    auto options = passthrough_options();
    options.max_doits_per_packet = 1;
    auto link = eth::SslbpPassthroughLink::open(eth::make_target(address, ch), options);
    CountingLink counting(*link);
    auto db = params::ParamDb::builtin();
    device::Amp8i20 amp(counting, db, ops::timing::amp());
    amp.identify();
    const auto all = dump_params(db);
    const Cost c = measure(link->port(), counting, 1, [&] { amp.read(all); });
    total.packets += c.packets;
    total.ms += c.ms;
    total.serial_us += c.serial_us;
  }
  return total;
}

// UDP requests the card has received: space 6 RXUDPCount (7I96S manual, "SPACE 6 LBP
// STATUS/CONTROL AREA"), 16 bits that wrap. The reading packet is counted on arrival, so
// it is part of the value it reads.
std::uint16_t requests_received(const eth::HostPort& host_port) {
  namespace lbp16 = lbp::lbp16;
  eth::UdpClient client(host_port.ip, host_port.port, ops::timing::udp({}, {}));
  const auto read = lbp16::read(lbp16::space::kStatus, eth::kRxUdpCountAddress, lbp16::Width::Bits16);
  return lbp16::words16(client.transact(std::span(&read, 1)).front()).front();
}

struct ProcessCost {
  double requests = 0;  // UDP requests per process, everything included
  double ms = 0;
};

// A whole program run against the card, `runs` times: its UDP requests as the card
// counted them, and its wall time.
ProcessCost per_process(const std::string& address, const std::vector<std::string>& command, int runs) {
  const auto host_port = eth::parse_host_port(address);
  ProcessCost c;
  for (int i = 0; i < runs; ++i) {
    const std::uint16_t before = requests_received(host_port);
    const auto t0 = Clock::now();
    if (bench::run_quiet(command) != 0)
      throw std::runtime_error(command.at(0) + " failed against " + address);
    c.ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    const std::uint16_t after = requests_received(host_port);
    c.requests += static_cast<std::uint16_t>(after - before - 1);  // less the second read itself
  }
  c.requests /= runs;
  c.ms /= runs;
  return c;
}

void row(const char* what, const Cost& before, const Cost& after) {
  std::printf("  %-44s %6.2f   %6.2f  (%4.2f per execute)  %7.3f ms  serial %6.0f us\n", what, before.packets,
              after.packets, after.executes > 0 ? after.packets / after.executes : after.packets, after.ms,
              after.serial_us);
}

}  // namespace

namespace {

int bench_main(int argc, char** argv) {
  const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 50;
  bench::SimProcess one({"--eth", "127.0.0.1:0"});
  const OneAmp before = one_amp(one.address(), 1, runs);
  const OneAmp after = one_amp(one.address(), 0, runs);

  std::printf(
      "Ethernet passthrough benchmark: i20sim --eth on loopback (a simulated 7I96S and 8I20s at 2.5 "
      "MBaud), not hardware\n");
  std::printf(
      "  UDP request packets per operation: one LBP command per packet (before) and batched (now);\n");
  std::printf(
      "  then time per operation and the serial time of its DOITs at 2.5 MBaud (estimated from the "
      "frame sizes)\n");
  std::printf("  %-44s %6s   %6s\n", "", "before", "now");
  row("read a working parameter", before.ram_read, after.ram_read);
  row("read an NV parameter", before.nv_read, after.nv_read);
  row("write+verify a working parameter", before.ram_write, after.ram_write);
  row("write+verify an NV parameter (device layer)", before.nv_write, after.nv_write);
  row("write+verify an NV parameter (one batch)", before.nv_write_one_batch, after.nv_write_one_batch);
  row("write+verify an NV parameter (two batches)", before.nv_write_two_batches, after.nv_write_two_batches);
  char dump_label[64];
  std::snprintf(dump_label, sizeof dump_label, "dump, %zu parameters", after.dump_size);
  row(dump_label, before.dump, after.dump);
  std::printf(
      "  the device layer sends an NV write as %.0f execute() calls (enter NV mode; check, write, read "
      "back, check; leave)\n",
      after.nv_write.executes);
  std::printf("  DOITs still busy at their read-back (polled or replayed): %llu\n",
              static_cast<unsigned long long>(after.late));

  const std::string i20 = (i20::test::bin_dir() / "i20").string();
  const int process_runs = std::max(1, runs / 10);
  const ProcessCost get = per_process(
      one.address(), {i20, "--no-user-params", "--eth", one.address(), "--channel", "0", "get", "BUSV"},
      process_runs);
  const ProcessCost dump =
      per_process(one.address(), {i20, "--no-user-params", "--eth", one.address(), "--channel", "0", "dump"},
                  process_runs);
  std::printf("  UDP requests per i20 process (as the card counts them: RXUDPCount, mean of %d):\n",
              process_runs);
  std::printf("    i20 --eth ADDR get BUSV  %6.2f requests %8.2f ms; the job itself (one read) %.2f\n",
              get.requests, get.ms, after.ram_read.packets);
  std::printf("    i20 --eth ADDR dump      %6.2f requests %8.2f ms; the job itself (the dump) %.2f\n",
              dump.requests, dump.ms, after.dump.packets);

  constexpr unsigned kAmps = 4;
  bench::SimProcess four({"--eth", "127.0.0.1:0", "--card", "7i92t", "--channels", std::to_string(kAmps)});
  const Cost one_by_one = four_amps_one_by_one(four.address(), kAmps);
  const Cost together =
      four_amps_one_execute(four.address(), kAmps, after.dump_batch, std::max(3, runs / 10));
  const Cost shared = four_amps_shared(four.address(), kAmps, std::max(3, runs / 10));
  std::printf("  dump of %u 8I20s on one 7I92T port:\n", kAmps);
  std::printf(
      "    one link each, one after the other, one command per packet (before) %6.2f packets %7.3f ms\n",
      one_by_one.packets, one_by_one.ms);
  std::printf(
      "    one execute() for all four channels                                 %6.2f packets %7.3f ms, "
      "serial %6.0f us\n",
      together.packets, together.ms, together.serial_us);
  std::printf(
      "    a thread and a link each on the shared port (as a fleet)            %6.2f packets %7.3f ms "
      "(a thread later than the %lld us gather window runs alone)\n",
      shared.packets, shared.ms, static_cast<long long>(ops::timing::kPassthroughGatherWindow.count()));

  std::printf("Targets (request packets):\n");
  std::printf("  dump of one 8I20 <= 2:                 %5.2f  %s\n", after.dump.packets,
              verdict(after.dump.packets, 2));
  std::printf("  dump of %u 8I20s on one port <= 3:      %5.2f  %s (one execute; %.2f with a thread each)\n",
              kAmps, together.packets, verdict(together.packets, 3), shared.packets);
  std::printf(
      "  NV write with verify <= 2:             %5.2f  %s as one batch, %.2f as two (%s), %.2f through "
      "this branch's device layer (%s, %.0f execute() calls)\n",
      after.nv_write_one_batch.packets, verdict(after.nv_write_one_batch.packets, 2),
      after.nv_write_two_batches.packets, verdict(after.nv_write_two_batches.packets, 2),
      after.nv_write.packets, verdict(after.nv_write.packets, 2), after.nv_write.executes);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return i20::bench::run_main([&] { return bench_main(argc, argv); });
}
