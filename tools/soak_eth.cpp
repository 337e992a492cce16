// SPDX-License-Identifier: GPL-2.0-or-later
// i20-soak N SEED --eth: the serial soak's scenarios over the Ethernet path. Each scenario
// starts a virtual 7I96S (one 8I20) or 7I92T (1 to 4 8I20s on one SSERIAL port) on
// 127.0.0.1:0 in this process, behind the fault proxy (ethsim/faulty_network.hpp), and
// opens the card through the proxy as the apps do (ops::open_link's Ethernet link, or the
// fleet's shared port). One injection per scenario: the network (lost, repeated, reordered,
// late or cut datagrams), the 8I20 behind the passthrough (the serial soak's injections),
// the card resetting or losing power, or another host starting normal mode. Judged by the
// simulators' memory with the serial soak's judge, plus the SSERIAL port and the host.
#include "soak_eth.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <thread>

#include "eth/passthrough_link.hpp"
#include "ethsim/board_control.hpp"
#include "ethsim/faulty_network.hpp"
#include "ethsim/server.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/core/timing.hpp"
#include "ops/fleet.hpp"
#include "sim/control.hpp"
#include "sim/ground_truth.hpp"
#include "sim/param_map.hpp"
#include "soak_common.hpp"

namespace i20::soak {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

constexpr unsigned kTimeoutMs = 50;  // the apps' default reply timeout

enum class Where { Amplifier, Network, Board };

struct EthScenario {
  Scenario s;
  ethsim::BoardKind kind = ethsim::BoardKind::I7i96s;
  unsigned port = 0, amplifiers = 1, channel = 0;
  Where where = Where::Amplifier;
  ethsim::NetworkFaults net{};
  std::string card_line;    // "card reset 5", "card power-loss 300", "host on"
  unsigned card_after = 0;  // exchanges before the card line (single) or 0.5 ms steps (fleet)
};

EthScenario next(Generator& gen) {
  EthScenario e;
  e.s = gen.next();  // the serial injection is drawn (and kept for Where::Amplifier)
  e.kind = gen.pick<ethsim::BoardKind>({ethsim::BoardKind::I7i96s, ethsim::BoardKind::I7i92t});
  if (e.kind == ethsim::BoardKind::I7i92t) {
    e.port = static_cast<unsigned>(gen.between(0, 1));
    e.amplifiers = static_cast<unsigned>(gen.between(1, 4));
    e.channel = static_cast<unsigned>(gen.between(0, e.amplifiers - 1));
  }
  e.where = gen.pick<Where>({Where::Amplifier, Where::Network, Where::Board});
  Injection& i = e.s.injection;
  if (e.where == Where::Network) {
    i = Injection{};
    auto& f = e.net;
    f.seed = static_cast<std::uint64_t>(gen.between(1, 1 << 30));
    const auto way = gen.between(0, 2);
    f.requests = way != 1, f.replies = way != 0;
    const char* ways[] = {" requests", " replies", ""};
    switch (gen.between(0, 4)) {
      case 0:
        f.drop_share = gen.pick<double>({0.02, 0.1});
        i.label = "net drop " + std::to_string(f.drop_share).substr(0, 4);
        break;
      case 1:
        f.duplicate_share = gen.pick<double>({0.03, 0.1});
        f.max_delay = 100ms;
        i.label = "net duplicate " + std::to_string(f.duplicate_share).substr(0, 4);
        break;
      case 2:
        f.delay_share = 0.2, f.min_delay = 1ms, f.max_delay = 30ms;
        i.label = "net reorder 0.2";
        break;
      case 3:
        f.delay_share = gen.pick<double>({0.05, 0.15}), f.min_delay = 60ms, f.max_delay = 250ms;
        i.label = "net late " + std::to_string(f.delay_share).substr(0, 4);
        break;
      case 4:
        f.truncate_share = gen.pick<double>({0.02, 0.1});
        i.label = "net truncate " + std::to_string(f.truncate_share).substr(0, 4);
        break;
    }
    i.label += ways[way];
    i.heal = gen.healing();
  } else if (e.where == Where::Board) {
    i = Injection{};
    e.card_after = static_cast<unsigned>(gen.between(1, 60));
    switch (gen.between(0, 2)) {
      case 0:
        e.card_line = "card reset 5";
        i.heal = 5ms;
        i.label = "card reset";
        break;
      case 1: {
        const auto ms = gen.pick<std::int64_t>({20, 300, 1500, 3000});
        e.card_line = "card power-loss " + std::to_string(ms);
        i.heal = std::chrono::milliseconds(ms);
        i.label = "card power-loss " + std::to_string(ms) + " ms";
        break;
      }
      case 2:
        e.card_line = "host on 1 port " + std::to_string(e.port);
        i.label = "host on";
        break;
    }
  }
  return e;
}

const char* mode_name(ethsim::ChannelMode m) {
  switch (m) {
    case ethsim::ChannelMode::Stopped: return "stopped";
    case ethsim::ChannelMode::Setup: return "setup";
    case ethsim::ChannelMode::Normal: return "normal";
  }
  return "?";
}

class Bench {
 public:
  Bench(const EthScenario& e, const params::ParamDb& db)
      : server_(options(e, db)), net_(server_.address(), {}) {
    server_.start();
  }
  ethsim::BoardServer& server() { return server_; }
  ethsim::FaultyNetwork& net() { return net_; }
  std::string url(const EthScenario& e, unsigned channel) const {
    return "eth://" + net_.address() + "/port" + std::to_string(e.port) + "/ch" + std::to_string(channel);
  }
  sim::GroundTruth capture(const EthScenario& e, unsigned channel) {
    return server_.with_card(
        [&](ethsim::VirtualBoard& c) { return sim::capture(*server_.amplifier(c, e.port, channel)); });
  }
  sim::RegisterMap map(const EthScenario& e) {
    return server_.with_card(
        [&](ethsim::VirtualBoard& c) { return server_.amplifier(c, e.port, 0)->amplifier().map(); });
  }
  // The control lines of the 8I20 injection, to one channel or to all.
  void control(const EthScenario& e, const std::vector<std::string>& lines, std::optional<unsigned> channel) {
    for (const auto& line : lines)
      for (unsigned ch = 0; ch < e.amplifiers; ++ch)
        if (!channel || *channel == ch)
          ethsim::apply_board_control(
              server_, "port " + std::to_string(e.port) + " ch " + std::to_string(ch) + " " + line);
  }

 private:
  static ethsim::ServerOptions options(const EthScenario& e, const params::ParamDb& db) {
    ethsim::ServerOptions o;
    o.listen = eth::HostPort{.ip = "127.0.0.1", .port = 0};
    o.card = e.kind;
    o.amplifiers.clear();
    for (unsigned ch = 0; ch < e.amplifiers; ++ch) o.amplifiers.push_back({e.port, ch});
    o.amplifier.map = sim::register_map_from(db);
    o.amplifier.reset_time = e.s.injection.reset_time;
    o.amplifier.world.bus_volts = e.s.busv;
    return o;
  }
  ethsim::BoardServer server_;
  ethsim::FaultyNetwork net_;
};

// The port and the host after the run, into the judged result of the card run that
// carries them (the first one). The host a card line starts runs channel 0 (HostOptions).
// `acted`: the card line ran (a run shorter than its exchange count never starts the host).
void judge_port(Bench& b, const EthScenario& e, Tally& t, Judged& j, bool acted) {
  const bool host = acted && e.card_line.rfind("host", 0) == 0;
  std::this_thread::sleep_for(40ms);  // the host runs on, the port finishes what it was given
  const bool running = b.server().host_running();
  bool stuck = false, host_channel_normal = true;
  b.server().with_card([&](ethsim::VirtualBoard& c) {
    auto& port = c.sslbp(e.port);
    // A running host keeps COMMAND busy with its DOITs; without one it must go idle.
    stuck = port.held_in_reset() || (port.busy() && !running);
    for (unsigned ch = 0; ch < e.amplifiers; ++ch) ++t.port_left[mode_name(port.mode(ch))];
    host_channel_normal = port.mode(0) == ethsim::ChannelMode::Normal;
    return 0;
  });
  if (stuck) {
    ++t.port_stuck;
    j.other.push_back("SSERIAL port left held in reset or busy");
  }
  if (!host) return;
  ++t.host_runs;
  const auto stats = b.server().host_stats();
  std::string why;
  if (!running || !stats)
    why = "the host that started mid-run is not running after it";
  else if (!host_channel_normal)
    why = "the running host's ch0 is no longer in normal mode";
  else if (stats->failed_cycles > 0)
    why = "the running host had " + std::to_string(stats->failed_cycles) + " failed cycles";
  if (why.empty()) return;
  ++t.host_disturbed;
  j.other.push_back(why);
}

// After the run: every held datagram delivered, every 8I20 injection off.
void quiesce(Bench& b, const EthScenario& e) {
  b.net().set_faults({});
  b.net().wait_idle(3s);
  b.control(e, {"corrupt 0", "drop 0", "reset-after off", "mute-after off", "eeprom-power-loss off"},
            std::nullopt);
  std::this_thread::sleep_for(e.s.injection.heal && *e.s.injection.heal > 1s ? *e.s.injection.heal : 0ms);
}

// Another 8I20 on the port must hold what it held: nothing was asked of it.
void judge_neighbours(Bench& b, const EthScenario& e, const sim::RegisterMap& map,
                      const std::vector<sim::GroundTruth>& before, unsigned target, Judged& j) {
  for (unsigned ch = 0; ch < e.amplifiers; ++ch) {
    if (ch == target) continue;
    const auto after = b.capture(e, ch);
    for (const auto& c : sim::unexplained_changes(map, before[ch], after, {}))
      j.stray.push_back("ch" + std::to_string(ch) + ", not a target: " + c);
    if (after.nv_access != lbp::local::NvAccess::Ram || after.rpcmem)
      j.stray.push_back("ch" + std::to_string(ch) + ", not a target, left in NV access/RPC memory mode");
  }
}

void run_single(const EthScenario& e, std::size_t index, const params::ParamDb& db, const fs::path& dir,
                Tally& t, bool verbose) {
  const Scenario& s = e.s;
  Bench b(e, db);
  const auto map = b.map(e);
  std::vector<sim::GroundTruth> before;
  for (unsigned ch = 0; ch < e.amplifiers; ++ch) before.push_back(b.capture(e, ch));
  ops::StopRequest stop;
  const ops::Cancel cancel(stop, [](const std::string&) {});
  const auto profile = profile_of(s, db);
  const auto request = request_for(profile, db, cancel, dir, s.path, kTimeoutMs);
  const auto endpoint = ops::parse_endpoint(b.url(e, e.channel));
  std::unique_ptr<ops::Amp> amp;
  InjectingLink* link = nullptr;
  try {
    auto inner = ops::open_link(endpoint, db, request.open.link, request.open.retry);
    auto wrapped = std::make_unique<InjectingLink>(std::move(inner), stop);
    link = wrapped.get();
    amp = ops::Amp::attach(std::move(wrapped), endpoint, db, request.open.retry, cancel);
  } catch (const Error& ex) {
    t.findings.push_back("#" + std::to_string(index) +
                         ": the card could not be opened without a fault: " + ex.what());
    return;
  }
  const auto& i = s.injection;
  if (e.where == Where::Amplifier) {
    b.control(e, i.control, e.channel);
    if (i.heal) link->heal_with(*i.heal, [&] { b.control(e, i.undo, e.channel); });
  } else if (e.where == Where::Network) {
    b.net().set_faults(e.net);
    if (i.heal) link->heal_with(*i.heal, [&] { b.net().set_faults({}); });
  } else {
    link->at(e.card_after, [&] { ethsim::apply_board_control(b.server(), e.card_line); });
    if (i.heal) link->heal_with(*i.heal, [] {});  // the card comes back by itself
  }
  if (i.cancel_after) link->arm_signal(i);
  ops::TargetRun run;
  try {
    run = ops::run_apply_on(*amp, ops::make_apply_job(request));
  } catch (const Error& ex) {
    run.outcome = ops::outcome_of(ex.kind());
    run.error = ex.what();
  }
  link->settle();
  if (i.self_heals) link->self_healed();
  const bool failed = link->failed();
  const bool healed = link->healed_within(2s);
  const bool acted = link->acted();
  amp.reset();  // closes the link as the apps do when they exit
  quiesce(b, e);
  auto j = judge(map, before[e.channel], b.capture(e, e.channel), run, cells_written(s, db));
  judge_neighbours(b, e, map, before, e.channel, j);
  judge_port(b, e, t, j, acted);
  record(t, s, index, run, j, verbose, failed ? std::optional<bool>(healed) : std::nullopt);
}

// Every 8I20 on the port is a target: one fleet run, their commands sharing DOITs.
void run_fleet(const EthScenario& e, std::size_t index, const params::ParamDb& db, const fs::path& dir,
               Tally& t, bool verbose) {
  const Scenario& s = e.s;
  Bench b(e, db);
  const auto map = b.map(e);
  std::vector<sim::GroundTruth> before;
  std::vector<ops::Endpoint> targets;
  for (unsigned ch = 0; ch < e.amplifiers; ++ch) {
    before.push_back(b.capture(e, ch));
    targets.push_back(ops::parse_endpoint(b.url(e, ch), ch));
  }
  ops::StopRequest stop;
  const auto profile = profile_of(s, db);
  const auto request =
      request_for(profile, db, ops::Cancel(stop, [](const std::string&) {}), dir, s.path, kTimeoutMs);
  const auto& i = s.injection;
  // The fleet opens its own links: the injections start with it, the timed ones (signals,
  // the card line) after 0.5 ms steps; no heal is measured here.
  if (e.where == Where::Amplifier) b.control(e, i.control, std::nullopt);
  if (e.where == Where::Network) b.net().set_faults(e.net);
  std::thread timed;
  if (i.cancel_after || e.where == Where::Board)
    timed = std::thread([&] {
      const unsigned steps = i.cancel_after ? *i.cancel_after : e.card_after;
      std::this_thread::sleep_for(std::chrono::microseconds(500 * steps) + 5ms);
      if (!i.cancel_after) {
        ethsim::apply_board_control(b.server(), e.card_line);
        return;
      }
      stop.request(i.signal);
      if (!i.again_after) return;
      std::this_thread::sleep_for(std::chrono::microseconds(500 * *i.again_after));
      stop.request(i.signal);
    });
  const auto runs = fleet_runs(targets, request);
  if (timed.joinable()) timed.join();
  quiesce(b, e);
  for (std::size_t ch = 0; ch < runs.size(); ++ch) {
    auto j = judge(map, before[ch], b.capture(e, static_cast<unsigned>(ch)), runs[ch], s.values);
    if (ch == 0) judge_port(b, e, t, j, true);  // the timed card line always runs
    record(t, s, index, runs[ch], j, verbose);
  }
}

}  // namespace

int run_eth_soak(std::size_t n, std::uint64_t seed, const std::vector<std::size_t>& only,
                 const params::ParamDb& db, bool verbose) {
  const auto dir = fs::temp_directory_path() / ("i20-soak-eth-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Generator gen(seed);
  Tally tally;
  std::size_t i96 = 0, i92 = 0;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < n; ++k) {
    const EthScenario e = next(gen);
    if (!only.empty() && std::find(only.begin(), only.end(), k) == only.end()) continue;
    ++(e.kind == ethsim::BoardKind::I7i96s ? i96 : i92);
    try {
      if (e.s.path == Path::Fleet)
        run_fleet(e, k, db, dir, tally, verbose);
      else
        run_single(e, k, db, dir, tally, verbose);
    } catch (const std::exception& ex) {
      tally.findings.push_back("#" + std::to_string(k) + ": the soak itself failed: " + ex.what());
    }
  }
  for (const auto& [v, c] : tally.outcomes) tally.scenarios += c;
  fs::remove_all(dir);
  const std::string what = "ethernet, in-process virtual 7I96S (" + std::to_string(i96) +
                           " scenarios) and 7I92T (" + std::to_string(i92) + ") through the fault proxy";
  print(tally, only.empty() ? n : only.size(), seed,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), what,
        "a fleet scenario is every 8I20 on the port, 1 to 4", true);
  return clean(tally) ? 0 : 1;
}

}  // namespace i20::soak
