// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 --eth IP watch|faults|scan --passive` beside the simulator's running host (issue 18
// item 4): the right values for every channel, timestamped change lines, the running
// machine untouched (no failed DOIT, no watchdog fault) and the request rate bound.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <regex>
#include <string>
#include <vector>

#include "fixtures.hpp"
#include "harness.hpp"

using namespace i20::test;

namespace {

using Transport = SimProcess::Transport;

Result run_i20(const std::vector<std::string>& args) {
  std::vector<std::string> all{"--no-user-params"};
  all.insert(all.end(), args.begin(), args.end());
  return run("i20", all);
}

// The stand-in's DOITs so far ("..., N DOITs (F failed)").
unsigned long host_doits(const std::string& host) {
  const auto end = host.find(" DOITs");
  if (end == std::string::npos) return 0;
  const auto begin = host.rfind(' ', end - 1);
  return std::stoul(host.substr(begin + 1, end - begin - 1));
}

// Whether the stand-in kept its DOITs within the 8I20's 40 ms watchdog ("longest gap N ms").
// A starved stand-in (its own process late, as a sanitizer build under load can be) lets the
// watchdog bite whatever a client does: then a watchdog fault is not the client's doing, and
// the tests say so instead of judging it.
bool host_kept_time(const std::string& host) {
  const auto at = host.find("longest gap ");
  if (at == std::string::npos) {
    ADD_FAILURE() << "the stand-in did not say its longest gap: " << host;
    return true;
  }
  const bool kept = std::stoul(host.substr(at + 12)) < 40;
  if (!kept) std::cout << "the stand-in host was starved past the watchdog (" << host << "): not judged\n";
  return kept;
}

// Two 8I20s on a 7I92T's port 0, run by the LinuxCNC stand-in; returns once it cycles.
struct RunningMachine {
  SimProcess sim{{"--card", "7i92t", "--channels", "2", "--running-host"}, Transport::Eth};
  RunningMachine() {
    const bool cycling =
        eventually([&] { return host_doits(sim.control("host")) >= 50; }, std::chrono::seconds(30));
    EXPECT_TRUE(cycling) << sim.control("host");
  }
  std::string address() const { return sim.port(); }
};

// Everything a child printed so far, read as it comes.
class Output {
 public:
  explicit Output(int fd) : fd_(fd) {}
  // Reads until `text` has come (searching from `from`), for at most 30 s.
  bool wait_for(const std::string& text, std::size_t from = 0) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (seen_.find(text, from) == std::string::npos && std::chrono::steady_clock::now() < deadline)
      if (!pump(100)) break;
    return seen_.find(text, from) != std::string::npos;
  }
  // Reads to the end (the child exited).
  void drain() {
    while (pump(5000)) {
    }
  }
  const std::string& text() const { return seen_; }

 private:
  bool pump(int ms) {
    pollfd p{.fd = fd_, .events = POLLIN, .revents = 0};
    if (poll(&p, 1, ms) <= 0) return true;
    char buffer[1024];
    const ssize_t n = read(fd_, buffer, sizeof buffer);
    if (n <= 0) return false;
    seen_.append(buffer, static_cast<std::size_t>(n));
    return true;
  }
  int fd_;
  std::string seen_;
};

}  // namespace

TEST(EthPassive, ScanListsEveryChannelTheHostRunsWithItsBusVoltage) {
  RunningMachine m;
  m.sim.control("ch 1 busv 48");
  // The control line lands at the 8I20 at once; the registers follow the host's next DOIT.
  Result r;
  ASSERT_TRUE(eventually([&] {
    r = run_i20({"--eth", m.address(), "scan", "--passive"});
    return r.out.find("ch 1: 8I20 run by the host, BUSV 48.00 V") != std::string::npos;
  })) << r.out
      << r.err;
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("ch 0: 8I20 run by the host, BUSV 320.00 V, FAULT 0x0000"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("hm2_7i92.0.8i20.0.1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("host: running"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 8I20(s) in the running host's cycle"), std::string::npos) << r.out;
  const auto host = m.sim.control("host");
  EXPECT_NE(host.find("ch 0 1,"), std::string::npos) << host;
  EXPECT_NE(host.find("(0 failed)"), std::string::npos) << host;
}

TEST(EthPassive, FaultsExplainsEachChannelFromTheFaultTable) {
  RunningMachine m;
  m.sim.control("ch 1 fault overcurrent on");
  Result r;
  ASSERT_TRUE(eventually([&] {
    r = run_i20({"--eth", m.address(), "--json", "faults", "--passive"});
    return r.out.find("CURRENTFAULT") != std::string::npos;
  })) << r.out
      << r.err;
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = run_i20({"--eth", m.address(), "faults", "--passive"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const auto ch0 = r.out.find("port 0 ch 0: BUSV 320.00 V  TEMP ");
  const auto ch1 = r.out.find("port 0 ch 1: BUSV 320.00 V  TEMP ");
  ASSERT_NE(ch0, std::string::npos) << r.out;
  ASSERT_NE(ch1, std::string::npos) << r.out;
  // Channel 1's section names the fault with the table's advice; channel 0 has none.
  EXPECT_NE(r.out.find("CURRENTFAULT", ch1), std::string::npos) << r.out;
  const auto host = m.sim.control("host");
  if (host_kept_time(host)) {
    EXPECT_NE(r.out.find("FAULT 0x0000: no faults", ch0), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("WATCHDOGFAULT"), std::string::npos) << "the host's 8I20s never missed a DOIT\n"
                                                              << r.out;
  }
  EXPECT_NE(host.find("(0 failed)"), std::string::npos) << host;
}

TEST(EthPassive, WatchPrintsTimestampedChangesAndLeavesTheMachineRunning) {
  RunningMachine m;
  const auto doits_before = host_doits(m.sim.control("host"));
  const Child watch = start("i20", {"--no-user-params", "--eth", m.address(), "watch", "--passive", "--plain",
                                    "--interval", "50", "--duration", "60"});
  Output out(watch.out_fd);
  ASSERT_TRUE(out.wait_for("port 0 ch 1: 8I20 in the host's cycle: bus 320.00 V")) << out.text();
  ASSERT_TRUE(out.wait_for("port 0 ch 0: 8I20 in the host's cycle: bus 320.00 V")) << out.text();
  const auto mark = out.text().size();
  m.sim.control("ch 1 busv 30");
  ASSERT_TRUE(out.wait_for("port 0 ch 1: bus voltage 320.00 V -> 30.00 V", mark)) << out.text();
  m.sim.control("ch 0 fault overcurrent on");
  ASSERT_TRUE(out.wait_for("port 0 ch 0: FAULT set: CURRENTFAULT (bit 4)", mark)) << out.text();
  kill(watch.pid, SIGINT);
  out.drain();
  int status = 0;
  waitpid(watch.pid, &status, 0);
  close(watch.out_fd);
  close(watch.err_fd);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 130) << status;
  const std::string& text = out.text();
  // Each change is a line of its own that starts with the time it was seen.
  EXPECT_TRUE(std::regex_search(
      text,
      std::regex(R"((^|\n)\d\d:\d\d:\d\d\.\d\d\d  \* port 0 ch 1: bus voltage 320\.00 V -> 30\.00 V\n)")))
      << text;
  EXPECT_TRUE(std::regex_search(
      text, std::regex(R"((^|\n)\d\d:\d\d:\d\d\.\d\d\d  \* port 0 ch 0: FAULT set: CURRENTFAULT)")))
      << text;
  // Channel 1's under-voltage is decoded by the fault table too.
  EXPECT_NE(text.find("port 0 ch 1: FAULT set: BUSLOVFAULT (bit 8)"), std::string::npos) << text;
  // The rate bound: survey + samples spaced >= 50 ms apart.
  std::smatch sm;
  ASSERT_TRUE(
      std::regex_search(text, sm, std::regex(R"((\d+) samples in ([0-9.]+) s, .* (\d+) UDP requests)")))
      << text;
  const double seconds = std::stod(sm[2]);
  const auto requests = std::stoul(sm[3]);
  EXPECT_GT(requests, 2u);
  EXPECT_LE(static_cast<double>(requests), 20.0 * seconds + 2.0) << text;
  // The machine ran on: more DOITs, none failed, no watchdog fault on any 8I20.
  const auto host = m.sim.control("host");
  EXPECT_GT(host_doits(host), doits_before) << host;
  EXPECT_NE(host.find("(0 failed)"), std::string::npos) << host;
  if (host_kept_time(host)) {
    EXPECT_EQ(text.find("WATCHDOG"), std::string::npos) << text;
  }
}

TEST(EthPassive, WatchJsonHasOneObjectPerSampleWithEveryAmplifier) {
  RunningMachine m;
  const auto r = run_i20({"--eth", m.address(), "--json", "watch", "--passive", "--count", "3"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"type\":\"start\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"max_requests_per_second\":20"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"kind\":\"joined\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"channel\":1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"busv_v\":320"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"type\":\"summary\""), std::string::npos) << r.out;
}

TEST(EthPassive, ARefusedNormalReadPointsToPassive) {
  RunningMachine m;
  const auto r = run_i20({"--eth", m.address(), "get", "BUSV"});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.err.find("another host is running the card"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("watch --passive"), std::string::npos) << r.err;
  EXPECT_NE(m.sim.control("host").find("(0 failed)"), std::string::npos);
}

TEST(EthPassive, PassiveWithoutAnEthernetCardIsBadInput) {
  for (const std::string command : {"watch", "faults", "scan"}) {
    const auto r = run_i20({"--sim", command, "--passive"});
    EXPECT_EQ(r.exit_code, 2) << command << ": " << r.err;
    EXPECT_NE(r.err.find(command + " --passive"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--eth"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line: " << r.err;
  }
  const auto r = run_i20({"--eth", "127.0.0.1:1", "watch", "--passive", "--interval", "20"});
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("at most 20 requests a second"), std::string::npos) << r.err;
}

TEST(EthPassive, HelpDocumentsTheRateBound) {
  for (const std::string command : {"watch", "faults", "scan"}) {
    const auto help = run("i20", {command, "--help"});
    EXPECT_NE(help.out.find("--passive"), std::string::npos) << help.out;
    EXPECT_NE(help.out.find("at most 20 UDP requests a second"), std::string::npos) << help.out;
  }
}
