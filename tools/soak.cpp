// SPDX-License-Identifier: GPL-2.0-or-later
// i20-soak N SEED: N random write scenarios against the in-process virtual 8I20, each with
// one injected fault, every one judged by the simulator's own memory (EEPROM image, RAM,
// NV access and RPC memory flags), never by what the tool reports. Prints one table; the
// columns under "must be 0" are defects when they are not. Exit 1 if any of them is not 0.
// With --eth the same scenarios and judge run over the Ethernet path (soak_eth.cpp).
//
// Everything here runs against the simulator, not hardware.
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include "link/pipelined_link.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/core/timing.hpp"
#include "ops/fleet.hpp"
#include "sim/ground_truth.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"
#include "soak_common.hpp"
#include "soak_eth.hpp"

using namespace i20;
using namespace i20::soak;
namespace fs = std::filesystem;

namespace {

void run_single(const Scenario& s, std::size_t index, const params::ParamDb& db, const fs::path& dir,
                Tally& t, bool verbose, bool trace) {
  sim::SimOptions options;
  options.device.map = sim::register_map_from(db);
  options.device.reset_time = s.injection.reset_time;
  options.device.world.bus_volts = s.busv;
  auto stream = std::make_unique<sim::SimStream>(std::move(options));
  sim::SimStream& sim = *stream;
  // The programs' serial link, with a 5 ms reply timeout (the simulator answers at once).
  ops::LinkSettings settings;
  settings.timeout_ms = 5;
  const auto link_options = ops::timing::serial_link(settings, ops::RetryPolicy{});
  ops::StopRequest stop;
  const ops::Cancel cancel(stop, [](const std::string&) {});  // the apps print the acknowledgement
  const auto map = sim.with_card([](sim::Virtual8i20& c) { return c.amplifier().map(); });
  const auto profile = profile_of(s, db);
  const auto request = request_for(profile, db, cancel, dir, s.path, 5);
  auto link = std::make_unique<InjectingLink>(
      std::make_unique<link::PipelinedLink>(std::move(stream), link_options), stop);
  InjectingLink& signals = *link;
  std::unique_ptr<ops::Amp> amp;
  try {
    amp = ops::Amp::attach(std::move(link), ops::parse_endpoint("sim"), db, {}, cancel);
  } catch (const Error& e) {
    t.findings.push_back("#" + std::to_string(index) +
                         ": the card could not be opened without a fault: " + e.what());
    return;
  }
  const auto before = sim.with_card([](sim::Virtual8i20& c) { return sim::capture(c); });
  if (trace)
    sim.with_card([index](sim::Virtual8i20& c) {
      c.set_trace(
          [index](const std::string& line) { std::cerr << "  #" << index << " card: " << line << "\n"; });
      return 0;
    });
  for (const auto& line : s.injection.control) sim.control(line);
  if (s.injection.cancel_after) signals.arm_signal(s.injection);  // counted from here
  if (s.injection.heal)
    signals.heal_with(*s.injection.heal, [&sim, &s] {
      for (const auto& line : s.injection.undo) sim.control(line);
    });
  ops::TargetRun run;
  try {
    run = ops::run_apply_on(*amp, ops::make_apply_job(request));
  } catch (const Error& e) {
    run.outcome = ops::outcome_of(e.kind());
    run.error = e.what();
  }
  signals.settle();
  if (s.injection.self_heals) signals.self_healed();
  for (const char* off :
       {"corrupt 0", "drop 0", "reset-after off", "mute-after off", "eeprom-power-loss off"})
    sim.control(off);
  const auto after = sim.with_card([](sim::Virtual8i20& c) { return sim::capture(c); });
  record(
      t, s, index, run, judge(map, before, after, run, cells_written(s, db)), verbose,
      signals.failed() ? std::optional<bool>(signals.healed_within(std::chrono::seconds(2))) : std::nullopt);
}

// Three in-process simulators with their EEPROMs in files, the injection given to all of
// them as control lines; judged by the EEPROM images left on disk.
void run_fleet(const Scenario& s, std::size_t index, const params::ParamDb& db, const fs::path& dir, Tally& t,
               bool verbose) {
  const auto map = sim::register_map_from(db);
  std::vector<ops::Endpoint> targets;
  std::vector<sim::GroundTruth> before;
  for (int i = 0; i < 3; ++i) {
    const auto image = dir / ("card" + std::to_string(i) + ".eeprom");
    fs::remove(image);
    { sim::EepromStore(map, sim::kDefaultEepromBytes, image); }
    sim::GroundTruth g;
    std::ifstream in(image, std::ios::binary);
    g.eeprom.assign(std::istreambuf_iterator<char>(in), {});
    g.ram.assign(0x10000, 0);
    before.push_back(g);
    targets.push_back(ops::parse_endpoint("sim:" + image.string(), static_cast<std::size_t>(i)));
  }
  ops::StopRequest stop;
  const auto profile = profile_of(s, db);
  auto request = request_for(profile, db, ops::Cancel(stop, [](const std::string&) {}), dir, s.path, 5);
  request.open.link.sim_control = {"busv " + std::to_string(s.busv)};
  request.open.link.sim_control.insert(request.open.link.sim_control.end(), s.injection.control.begin(),
                                       s.injection.control.end());
  // A signal after a while (the one scenario kind whose timing is not fixed by the seed).
  std::thread signals;
  if (s.injection.cancel_after)
    signals = std::thread([&stop, i = s.injection] {
      std::this_thread::sleep_for(std::chrono::microseconds(500 * *i.cancel_after));
      stop.request(i.signal);
      if (!i.again_after) return;
      std::this_thread::sleep_for(std::chrono::microseconds(500 * *i.again_after));
      stop.request(i.signal);
    });
  const auto runs = fleet_runs(targets, request);
  if (signals.joinable()) signals.join();
  for (std::size_t i = 0; i < runs.size(); ++i) {
    sim::GroundTruth after = before[i];
    std::ifstream in(dir / ("card" + std::to_string(i) + ".eeprom"), std::ios::binary);
    after.eeprom.assign(std::istreambuf_iterator<char>(in), {});
    std::vector<std::pair<std::string, std::int64_t>> nv;
    for (const auto& v : s.values) nv.push_back(v);
    auto j = judge(map, before[i], after, runs[i], nv);
    j.modes_on = false;  // the process-local card is gone: only its EEPROM can be judged
    std::erase_if(j.crossed, [](const std::string& c) { return c.rfind("NV", 0) != 0; });
    record(t, s, index, runs[i], j, verbose);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const auto usage = [] {
    std::cerr << "usage: i20-soak N SEED [--eth] [--verbose] [--trace] [--only K]...\n"
                 "  --eth: over the Ethernet path (virtual 7I96S/7I92T, 1 to 4 8I20s on a port, in-process)\n"
                 "  N random write scenarios against the simulator; --only K runs just scenario K of them\n"
                 "  (the same scenario as in the full run: the generator still draws all N);\n"
                 "  --trace prints every command the virtual card executes (single-card scenarios)\n";
    return 2;
  };
  if (argc < 3) return usage();
  std::size_t n = 0;
  std::uint64_t seed = 0;
  bool verbose = false, trace = false, eth = false;
  std::vector<std::size_t> only;
  try {
    n = std::stoul(argv[1]);
    seed = std::stoull(argv[2]);
    for (int a = 3; a < argc; ++a) {
      const std::string arg = argv[a];
      if (arg == "--eth")
        eth = true;
      else if (arg == "--verbose")
        verbose = true;
      else if (arg == "--trace")
        trace = verbose = true;
      else if (arg == "--only" && a + 1 < argc)
        only.push_back(std::stoul(argv[++a]));
      else
        return usage();
    }
  } catch (const std::exception&) {
    return usage();
  }
  const auto db = params::ParamDb::builtin();
  const auto dir = fs::temp_directory_path() / ("i20-soak-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  if (eth) return run_eth_soak(n, seed, only, db, verbose);
  Generator gen(seed);
  Tally tally;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < n; ++i) {
    const Scenario s = gen.next();
    if (!only.empty() && std::find(only.begin(), only.end(), i) == only.end()) continue;
    if (s.path == Path::Fleet)
      run_fleet(s, i, db, dir, tally, verbose);
    else
      run_single(s, i, db, dir, tally, verbose, trace);
  }
  for (const auto& [v, c] : tally.outcomes) tally.scenarios += c;
  fs::remove_all(dir);
  print(tally, only.empty() ? n : only.size(), seed,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
        "serial, in-process virtual 8I20", "a fleet scenario is three cards", false);
  return clean(tally) ? 0 : 1;
}
