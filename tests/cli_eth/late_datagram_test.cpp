// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 18 item 1: `i20 set` over Ethernet through a network that holds datagrams back past
// the reply timeout (and repeats some). A request that arrives late still executes late, on
// SSLBP state the tool's later packets share; the tool must never report a change done
// that the card does not hold, nor leave the 8I20 in NV access or RPC memory mode.
// Judged by the virtual 8I20's memory after every held-back datagram was delivered.
#include <gtest/gtest.h>

#include <functional>
#include <iostream>
#include <map>

#include "ethsim/faulty_network.hpp"
#include "fixtures.hpp"
#include "harness.hpp"
#include "ops/core/timing.hpp"
#include "sim/ground_truth.hpp"

using namespace i20;
using namespace std::chrono_literals;

namespace {

ethsim::ServerOptions two_channel_7i92t() {
  ethsim::ServerOptions o;
  o.card = ethsim::BoardKind::I7i92t;
  o.amplifiers = {{0, 0}, {0, 1}};
  return o;
}

struct Trial {
  int exit_code = -1;
  bool false_done = false;   // exit 0, yet the card does not hold what was asked
  bool nv_left_on = false;   // NV access mode left on, whatever the exit
  bool rpc_left_on = false;  // RPC memory mode left on, whatever the exit
  bool false_reset = false;  // "reset itself" printed, yet the card did not reset
  std::string why;
};

class LateDatagrams : public ::testing::Test {
 protected:
  const std::vector<std::string> set_args = {"set", "NVKQP=119", "NVMAXCURRENT=5.00A"};

  // One `i20 set` through `faults` on a fresh card; the reference EEPROM is what a clean
  // run leaves.
  Trial trial(const ethsim::NetworkFaults& faults, const lbp::Bytes* reference,
              lbp::Bytes* eeprom_out = nullptr) {
    test::RunningBoard card(two_channel_7i92t());
    ethsim::FaultyNetwork network(card.address(), faults);
    const auto capture = [&] {
      return card.with_amplifier(0, 1, [](sim::Virtual8i20& a) { return sim::capture(a); });
    };
    const auto map = card.with_amplifier(0, 1, [](sim::Virtual8i20& a) { return a.amplifier().map(); });
    const auto before = capture();
    std::vector<std::string> args = {"--no-user-params", "--port", "eth://" + network.address() + "/ch1"};
    args.insert(args.end(), set_args.begin(), set_args.end());
    const auto r = test::run("i20", args);
    EXPECT_TRUE(network.wait_idle(5s)) << "the proxy still holds datagrams";
    const auto after = capture();
    if (eeprom_out) *eeprom_out = after.eeprom;
    Trial t;
    t.exit_code = r.exit_code;
    t.nv_left_on = after.nv_access != lbp::local::NvAccess::Ram;
    t.rpc_left_on = after.rpcmem;
    t.false_reset = r.out.find("reset itself") != std::string::npos && after.resets == before.resets;
    if (r.exit_code == 0) {
      const auto stray = sim::unexplained_changes(map, before, after, {"NVKQP", "NVMAXCURRENT"});
      if (reference && after.eeprom != *reference) t.why += "EEPROM differs from a clean run's; ";
      if (!stray.empty()) t.why += "stray change " + stray.front() + "; ";
      if (t.nv_left_on || t.rpc_left_on) t.why += "left in NV access/RPC mode; ";
      t.false_done = !t.why.empty();
    }
    if (t.false_done || t.nv_left_on || t.rpc_left_on || t.false_reset)
      std::cerr << "seed " << faults.seed << ": exit " << r.exit_code << ", " << t.why << "\n"
                << r.out << r.err;
    return t;
  }

  struct Tally {
    unsigned ok = 0, false_done = 0, nv_left_on = 0, rpc_left_on = 0, false_reset = 0;
  };

  // 30 trials through `shape` (seeds 1 to 30), judged against a clean run's EEPROM.
  Tally trials(ethsim::NetworkFaults shape) {
    lbp::Bytes reference;
    EXPECT_EQ(trial(ethsim::NetworkFaults{}, nullptr, &reference).exit_code, 0);
    Tally tally;
    const unsigned count = 30;
    for (unsigned seed = 1; seed <= count; ++seed) {
      shape.seed = seed;
      const Trial t = trial(shape, &reference);
      tally.ok += t.exit_code == 0;
      tally.false_done += t.false_done;
      tally.nv_left_on += t.nv_left_on;
      tally.rpc_left_on += t.rpc_left_on;
      tally.false_reset += t.false_reset;
    }
    std::cout << count << " trials: " << tally.ok << " exit 0, " << tally.false_done << " false done, "
              << tally.nv_left_on << " left in NV access mode, " << tally.rpc_left_on
              << " left in RPC memory mode, " << tally.false_reset << " false reset claims\n";
    return tally;
  }
};

TEST_F(LateDatagrams, CleanNetworkAppliesTheChange) {
  const Trial t = trial(ethsim::NetworkFaults{}, nullptr);
  EXPECT_EQ(t.exit_code, 0);
  EXPECT_FALSE(t.nv_left_on);
  EXPECT_FALSE(t.rpc_left_on);
}

// 10% of datagrams, both ways, held back 80-400 ms (past the 50 ms reply timeout), the
// issue's network: no false "done", never left in NV or RPC memory mode.
TEST_F(LateDatagrams, NoFalseDoneUnderDelayedAndRepeatedDatagrams) {
  const Tally t = trials(ethsim::NetworkFaults{.delay_share = 0.10});
  EXPECT_EQ(t.false_done, 0u);
  EXPECT_EQ(t.nv_left_on, 0u);
  EXPECT_EQ(t.rpc_left_on, 0u);
  // "The card reset itself (STATUS EXTR)" printed 3 times in 30 here while the card had not
  // reset: the fence took a late first packet's arrival for a lost DOIT packet's, and
  // STATUS was read from an older command's result (tests/eth/fenced_transport_test.cpp).
  EXPECT_EQ(t.false_reset, 0u);
  EXPECT_GT(t.ok, 0u) << "no trial got through: the test would pass a tool that always gives up";
}

// 5% of datagrams held back and 5% repeated (the copy up to 400 ms later). A copy that
// arrives after the tool's packet ran runs again by itself. Before every packet set and
// cleared the modes it needs (PassthroughPort's bracket): a repeated EEPROM-cell packet
// landed in normal access and wrote working memory at the cell's EEPROM address after
// "APPLIED AND VERIFIED" (seed 1), and a repeated first RPC-table packet of the opening
// turned RPC memory access on again, so a later read-back read the RPC table and the run
// ended rolled back with the mode left on (seed 27).
TEST_F(LateDatagrams, NoFalseDoneAndNoModeLeftOnUnderRepeatedDatagrams) {
  const Tally t = trials(ethsim::NetworkFaults{.delay_share = 0.05, .duplicate_share = 0.05});
  EXPECT_EQ(t.false_done, 0u);
  EXPECT_EQ(t.nv_left_on, 0u);
  EXPECT_EQ(t.rpc_left_on, 0u);
  EXPECT_GT(t.ok, 0u) << "no trial got through: the test would pass a tool that always gives up";
}

}  // namespace

namespace {

unsigned long runs_from(const char* variable, unsigned long otherwise) {
  const char* set = std::getenv(variable);
  return set ? std::stoul(set) : otherwise;
}

// What `wpd`, `i20 set` and a two-channel fleet did through a faulty network, judged on the
// virtual 8I20s' own memory once every held datagram was delivered.
struct Verdicts {
  unsigned late = 0, false_results = 0, modes_left = 0;
  double longest = 0;
  std::map<int, unsigned> exits;
};

// Runs the commands in turn, `runs` times, through `faults(seed)` (seeds 1 to runs; a
// command keeps its turn for `stride` seeds). A run over `bound_s` is late.
Verdicts run_through(const std::function<ethsim::NetworkFaults(unsigned)>& faults, unsigned long runs,
                     unsigned stride, double bound_s) {
  struct Command {
    std::string program;
    std::vector<std::string> args;  // {AT} stands for "eth://PROXY"
    std::vector<unsigned> channels;
    std::map<std::string, std::int64_t> expect;  // what exit 0 means the card holds
  };
  const std::string defaults = (test::source_dir() / "profiles" / "defaults.yaml").string();
  const std::vector<Command> commands = {
      {"wpd", {"--port", "{AT}/ch1", "NVMAXCURRENT", "950"}, {1}, {{"NVMAXCURRENT", 950}}},
      {"wpd", {"--port", "{AT}/ch0", "NVKQP", "100"}, {0}, {{"NVKQP", 100}}},
      {"i20",
       {"--no-user-params", "--port", "{AT}/ch1", "set", "NVKQP=119", "NVMAXCURRENT=5.00A"},
       {1},
       {{"NVKQP", 119}, {"NVMAXCURRENT", 500}}},
      {"i20",
       {"--no-user-params", "profile", "apply", defaults, "--target", "{AT}/ch0", "--target", "{AT}/ch1"},
       {0, 1},
       {}}};
  Verdicts v;
  // I20_FIRST_SEED: where a long manual run split over several processes starts.
  const auto first = static_cast<unsigned>(runs_from("I20_FIRST_SEED", 1));
  for (unsigned seed = first; seed < first + runs; ++seed) {
    test::RunningBoard card(two_channel_7i92t());
    ethsim::FaultyNetwork network(card.address(), faults(seed));
    const Command& c = commands[(seed - 1) / stride % commands.size()];
    std::vector<std::string> args;
    for (auto a : c.args) {
      if (const auto at = a.find("{AT}"); at != std::string::npos)
        a.replace(at, 4, "eth://" + network.address());
      args.push_back(a);
    }
    const auto capture = [&](unsigned ch) {
      return card.with_amplifier(0, ch, [](sim::Virtual8i20& a) { return sim::capture(a); });
    };
    std::map<unsigned, sim::GroundTruth> before;
    for (const unsigned ch : c.channels) before[ch] = capture(ch);
    const auto start = std::chrono::steady_clock::now();
    const auto r = test::run(c.program, args, {}, 120);
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    network.release_held();
    EXPECT_TRUE(network.wait_idle(5s));
    v.longest = std::max(v.longest, took);
    v.late += took > bound_s;
    ++v.exits[r.exit_code];
    std::string why;
    for (const unsigned ch : c.channels) {
      const auto map = card.with_amplifier(0, ch, [](sim::Virtual8i20& a) { return a.amplifier().map(); });
      const auto after = capture(ch);
      if (after.nv_access != lbp::local::NvAccess::Ram || after.rpcmem) {
        ++v.modes_left;
        why += "ch" + std::to_string(ch) + " left in NV access or RPC memory mode; ";
      }
      if (r.exit_code == 0)
        for (const auto& [cell, raw] : c.expect)
          if (sim::value_in(after, map.at(cell)) != static_cast<std::uint64_t>(raw))
            why +=
                "exit 0 but ch" + std::to_string(ch) + " " + cell + " is not " + std::to_string(raw) + "; ";
      // Exit 1 and 2 promise nothing was written.
      if ((r.exit_code == 1 || r.exit_code == 2) &&
          !sim::unexplained_changes(map, before[ch], after, {}).empty())
        why += "exit " + std::to_string(r.exit_code) + " but ch" + std::to_string(ch) + " changed " +
               sim::unexplained_changes(map, before[ch], after, {}).front() + "; ";
    }
    v.false_results += !why.empty();
    std::cout << "seed " << seed << " (" << c.program << " " << c.args[c.args.size() > 3 ? 3 : 0]
              << "): exit " << r.exit_code << " in " << took << " s" << (why.empty() ? "" : ": " + why)
              << "\n"
              << (why.empty() && !std::getenv("I20_LATE_VERBOSE") ? "" : r.out + r.err) << std::flush;
  }
  std::cout << runs << " runs: the longest took " << v.longest << " s (bound " << bound_s << " s); exits:";
  for (const auto& [code, n] : v.exits) std::cout << " " << n << "x" << code;
  std::cout << "; " << v.false_results << " false results, " << v.modes_left << " modes left on\n";
  return v;
}

// Issue 33 item 6: a network that reorders 30% of datagrams (odd seeds: overtaken by the
// next datagram; even seeds: held 1-30 ms). Every run must end well within the operation's
// deadline (RetryPolicy::operation_deadline, 20 s, plus the rollback and settle after it),
// with a true exit code. A hang is the defect the issue saw (5 of 12 runs, over 60 s).
TEST_F(LateDatagrams, ReorderingNetworkEndsWithinTheDeadlineWithATrueExitCode) {
  const auto v = run_through(
      [](unsigned seed) {
        const bool overtaken = seed % 2 == 1;
        ethsim::NetworkFaults faults{.seed = seed, .min_delay = 1ms, .max_delay = overtaken ? 2000ms : 30ms};
        (overtaken ? faults.reorder_share : faults.delay_share) = 0.30;
        return faults;
      },
      runs_from("I20_REORDER_RUNS", 12), 2, 30);
  EXPECT_EQ(v.late, 0u) << "a run took longer than 30 s";
  EXPECT_EQ(v.false_results, 0u);
  EXPECT_EQ(v.modes_left, 0u);
  EXPECT_GT(v.exits.count(0), 0u) << "no run got through: a tool that always gives up would pass";
}

// Issue 40: a proxy that holds 30% of datagrams, either way, until the next one has passed
// (NetworkFaults::hold_share): every exchange then waits out its reply timeout, backed off to
// the 1 s ceiling, and a packet with writes waits over all its attempts. Before the deadline
// was one (counted from the card's opening, every reply wait cut at it, nothing sent after
// it but the way back), `wpd` and `i20 set` ran up to 67.9 s. Each run must end within the
// bound README's "How long a command may take" states, with a true exit code. CI runs 8
// (I20_HOLD_RUNS sets more; the 100 per command are a manual run).
TEST_F(LateDatagrams, HoldingProxyEndsWithinTheStatedBoundWithATrueExitCode) {
  const auto bound = ops::timing::kOperationDeadline + ops::timing::kSettleBudget +
                     ops::timing::kLeaveModeBudget + ops::timing::kFenceBound +
                     ops::timing::kPortCloseBudget + 2 * ops::timing::kUdpMaxTimeout;
  const auto v =
      run_through([](unsigned seed) { return ethsim::NetworkFaults{.seed = seed, .hold_share = 0.30}; },
                  runs_from("I20_HOLD_RUNS", 8), 1, std::chrono::duration<double>(bound).count());
  EXPECT_EQ(v.late, 0u) << "a run took longer than the stated bound";
  EXPECT_EQ(v.false_results, 0u);
  EXPECT_EQ(v.modes_left, 0u);
}

// Issue 40: mild faults (5% of datagrams lost, 20% repeated, 10% late, either way) are ridden
// as before the deadline was one: at most 1 run in 10 ends without its change. How often a
// run gets through is a figure of the host's speed as much as of the tool's (every reply
// timeout, the fence's bound and the running-host watch are times): the sanitizer build,
// several times slower, walks the same paths a few times with I20_JUDGE_SUCCESS_RATE=0 and
// judges only what is never allowed (a false result, a mode left on, a run past the bound);
// the Release suite judges the rate. Before the opening of the port was retried after a link
// failure (PassthroughOptions::opening_attempts), a late or repeated datagram during it
// ended `i20 set` with exit 1 in 2 of 20 runs under the sanitizers.
TEST_F(LateDatagrams, MildFaultsRarelyEndWithoutTheChange) {
  const auto runs = runs_from("I20_MILD_RUNS", 10);
  const auto v = run_through(
      [](unsigned seed) {
        return ethsim::NetworkFaults{
            .seed = seed, .delay_share = 0.10, .duplicate_share = 0.20, .drop_share = 0.05};
      },
      runs, 1, 30);
  EXPECT_EQ(v.late, 0u);
  EXPECT_EQ(v.false_results, 0u);
  EXPECT_EQ(v.modes_left, 0u);
  const unsigned changed = v.exits.count(0) ? v.exits.at(0) : 0u;
  if (runs_from("I20_JUDGE_SUCCESS_RATE", 1) == 0) {
    std::cout << changed << " of " << runs << " runs got their change; the rate is not judged in this build\n";
    return;
  }
  EXPECT_GE(changed * 10, runs * 9) << runs - changed << " of " << runs << " runs ended without their change";
}

}  // namespace
