// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 7 end to end: the toolkit's commands work unchanged through a 7I96S's SSLBP
// passthrough, and one EEPROM image is one amplifier whichever way it is reached.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "fixtures.hpp"
#include "harness.hpp"

using namespace i20::test;

namespace {

using Transport = SimProcess::Transport;

Result run_i20(const std::vector<std::string>& target, std::vector<std::string> args) {
  args.insert(args.begin(), target.begin(), target.end());
  args.insert(args.begin(), "--no-user-params");
  return run("i20", args);
}

std::vector<std::string> eth(const SimProcess& sim) {
  return {"--eth", sim.port()};
}
std::vector<std::string> pty(const SimProcess& sim) {
  return {"--port", sim.port()};
}

}  // namespace

TEST(EthCli, NvWrittenOverEthernetReadsBackThroughTheSerialPort) {
  TempDir dir;
  const auto image = (dir / "amp.eeprom").string();
  {
    // The 8I20 on a 7I44 behind a 7I96S, on the manual's 120 V line.
    SimProcess card({"--eeprom", image, "--busv", "160"}, Transport::Eth);
    const auto r = run_i20(eth(card), {"set", "NVBRAKEONV=190V", "NVBRAKEOFFV=170V", "NVMAXCURRENT=7.5A"});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 3 values written"), std::string::npos) << r.out;
  }
  SimProcess bench({"--eeprom", image});  // the same amplifier moved to a 3I22 (W6 down)
  EXPECT_EQ(run_i20(pty(bench), {"get", "NVBRAKEONV", "NVBRAKEOFFV", "NVMAXCURRENT"}).out,
            "NVBRAKEONV = 190.00 V\nNVBRAKEOFFV = 170.00 V\nNVMAXCURRENT = 7.50 A\n");
}

TEST(EthCli, NvWrittenThroughTheSerialPortReadsBackOverEthernet) {
  TempDir dir;
  const auto image = (dir / "amp.eeprom").string();
  {
    SimProcess bench({"--eeprom", image, "--busv", "160"});  // a 120 V line: brake-off above its bus
    ASSERT_EQ(run("wpd", {"--port", bench.port(), "--no-user-params", "NVBRAKEOFFV", "17000"}).exit_code, 0);
  }
  SimProcess card({"--eeprom", image}, Transport::Eth);
  const auto r = run("rpd", {"--port", "eth://" + card.port() + "/ch0", "--no-user-params", "NVBRAKEOFFV"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "17000\n");
}

TEST(EthCli, EveryReadCommandWorksUnchanged) {
  SimProcess card({}, Transport::Eth);
  auto r = run_i20(eth(card), {"info"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("8I20 on eth://" + card.port() + "/ch0"), std::string::npos) << r.out;
  r = run_i20(eth(card), {"dump"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("NVKQI"), std::string::npos);
  EXPECT_NE(r.out.find("UNITNUMBER"), std::string::npos);
  r = run_i20({"--eth", card.port(), "--channel", "0"}, {"get", "--raw", "NVKQP", "BUSV"});
  EXPECT_EQ(r.out, "NVKQP = 50\nBUSV = 32000\n") << r.err;
}

TEST(EthCli, SafetyRefusalsSendNothingOverEthernetEither) {
  SimProcess card({}, Transport::Eth);
  const auto r = run_i20(eth(card), {"set", "NVMAXCURRENT=31A"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("outside its valid range"), std::string::npos) << r.err;
  EXPECT_EQ(run_i20(eth(card), {"get", "--raw", "NVMAXCURRENT"}).out, "NVMAXCURRENT = 1000\n");
}

TEST(EthCli, ScanListsTheCardItsPortAndThe8I20) {
  SimProcess card({}, Transport::Eth);
  const auto r = run_i20(eth(card), {"scan"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("7I96S at " + card.port()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("SSERIAL port 0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ch 0: 8I20 unit 74565"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("eth://" + card.port() + "/ch0"), std::string::npos) << r.out;
  const auto j = run_i20(eth(card), {"--json", "scan"});
  EXPECT_NE(j.out.find("\"is_8i20\": true"), std::string::npos) << j.out;
}

TEST(EthCli, FaultsReadLatchedFaultsWithoutClearingThemOnAnyFirmware) {
  // A shuffled map: the database's RAM addresses are wrong on this card, yet the card's own
  // RPC table names FAULT and STATUS, and the setup-mode passthrough reads them as they are.
  SimProcess card({"--random-map", "5", "--enable", "off"}, Transport::Eth);
  card.control("enable on");  // the fault stays latched; only CLEARFAULT (or a normal start) clears it
  for (int i = 0; i < 3; ++i) {
    const auto r = run_i20(eth(card), {"faults"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("FAULT 0x0002"), std::string::npos) << "read " << i << ": " << r.out;
    EXPECT_NE(r.out.find("NOENABLEFAULT"), std::string::npos) << r.out;
    EXPECT_EQ(r.err.find("not confirmed"), std::string::npos) << r.err;
  }
  EXPECT_EQ(card.control("get FAULT"), "2") << "reading faults must not clear them";
}

TEST(EthCli, WatchReportsLatchedFaultsBeforeNormalModeClearsThem) {
  SimProcess card({"--random-map", "5", "--enable", "off"}, Transport::Eth);
  card.control("enable on");
  card.control("busv 48");
  const auto r = run_i20(eth(card), {"watch", "--count", "3", "--plain", "--interval", "50"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto latched = r.out.find("FAULT set: NOENABLEFAULT");
  const auto notice = r.out.find("its start CLEARS the latched faults");
  EXPECT_NE(latched, std::string::npos) << r.out;
  EXPECT_NE(notice, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("BUSV 48.00 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 samples"), std::string::npos) << r.out;
}

TEST(EthCli, FleetAppliesToSerialAndEthernetTargetsTogether) {
  SimProcess bench({"--busv", "160"});  // both on the profile's 120 V line
  SimProcess card({"--busv", "160"}, Transport::Eth);
  const auto profile = (source_dir() / "profiles" / "line-120v.yaml").string();
  const auto r =
      run("i20", {"--no-user-params", "profile", "apply", profile, "--target", bench.port(), "--target",
                  "eth://" + card.port() + "/ch0", "--backup-dir", TempDir().path().string()});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(run_i20(eth(card), {"get", "NVBRAKEONV"}).out, "NVBRAKEONV = 190.00 V\n");
  EXPECT_EQ(run_i20(pty(bench), {"get", "NVBRAKEONV"}).out, "NVBRAKEONV = 190.00 V\n");
}

// ---- issue 12: safe beside a running machine, units, control, batching ---------------------

namespace {

// Waits up to 5 s for `path` to exist.
bool appears(const std::filesystem::path& path) {
  return eventually([&] { return std::filesystem::exists(path); });
}

// The DOITs the simulator's LinuxCNC stand-in has run ("..., N DOITs (F failed)"), 0 before
// it runs.
unsigned long host_doits(const std::string& host) {
  const auto end = host.find(" DOITs");
  if (end == std::string::npos) return 0;
  const auto begin = host.rfind(' ', end - 1);
  return std::stoul(host.substr(begin + 1, end - begin - 1));
}

// Reads `fd` (a child's stdout) until a line containing `text` has come, for at most 30 s.
// Whether `fd` prints `text` (after `after`, when given) within 30 s.
bool prints(int fd, const std::string& text, const std::string& after = "") {
  std::string seen;
  const auto found = [&] {
    const auto from = seen.find(after);
    return from != std::string::npos && seen.find(text, from + after.size()) != std::string::npos;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!found() && std::chrono::steady_clock::now() < deadline) {
    pollfd p{.fd = fd, .events = POLLIN, .revents = 0};
    if (poll(&p, 1, 100) <= 0) continue;
    char buffer[512];
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n <= 0) break;  // the child ended
    seen.append(buffer, static_cast<std::size_t>(n));
  }
  return found();
}

void write_line(const std::filesystem::path& fifo, const std::string& line) {
  std::ofstream out(fifo);
  out << line << "\n";
}

std::string get_raw(const SimProcess& sim, const std::string& name, unsigned channel = 0) {
  return run_i20({"--eth", sim.port(), "--channel", std::to_string(channel)}, {"get", "--raw", name}).out;
}

// Polls until `name` reads `expected` (the simulator applies control lines asynchronously).
// The reading is the event: a minute bounds it only so that a card that never takes the
// line fails the test (a sanitizer-built card on a loaded host may take seconds).
bool reads(const SimProcess& sim, const std::string& name, const std::string& expected,
           unsigned channel = 0) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  for (;;) {
    if (get_raw(sim, name, channel) == name + " = " + expected + "\n") return true;
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

}  // namespace

TEST(EthCli, ScanIsRefusedBesideARunningMachineAndTakeOverSaysWhatItDid) {
  SimProcess card({"--running-host"}, Transport::Eth);  // a LinuxCNC stand-in, DOITs every 1 ms
  // Until the stand-in has run some cycles (it starts on its own thread; a loaded machine
  // delays it).
  ASSERT_TRUE(eventually([&] { return host_doits(card.control("host")) >= 50; }, std::chrono::seconds(30)))
      << card.control("host");
  auto r = run_i20(eth(card), {"scan"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("refusing to stop and scan the SSERIAL ports"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("another host is running the card"), std::string::npos) << r.err;
  // One name for one thing: the refusal names the option every command takes (the app adds it).
  EXPECT_NE(r.err.find("take the port over: every axis on that port drops out (--take-over)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(card.control("host").find("(0 failed)") != std::string::npos, true) << "the machine runs on";
  r = run_i20(eth(card), {"scan", "--take-over"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("hm2_7i96s.0.8i20.0.0"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("scan --take-over: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("its axes dropped out"), std::string::npos) << r.err;
  // The old spelling still works for scripts, and says what replaced it.
  r = run_i20(eth(card), {"scan", "--force"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("`scan --force` is deprecated"), std::string::npos) << r.err;
  const auto help = run("i20", {"scan", "--help"});
  EXPECT_EQ(help.out.find("--force"), std::string::npos) << "the deprecated alias is hidden";
  EXPECT_NE(help.out.find("--take-over"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("drops every axis"), std::string::npos) << help.out;
}

TEST(EthCli, ScanIsRefusedBesideAWatch) {
  // The case: an `i20 --eth IP watch` in normal mode stands in for LinuxCNC.
  SimProcess card({}, Transport::Eth);
  const Child watch = start("i20", {"--no-user-params", "--eth", card.port(), "watch", "--plain",
                                    "--interval", "20", "--duration", "5"});
  // Its first sample in normal mode: the watch runs the card from now on. (Its first line of
  // all is read in setup mode, before it switches: a scan then can find the port between the
  // watch's stop and its start, with nobody running it.)
  ASSERT_TRUE(prints(watch.out_fd, "  BUSV ", "switching to SSLBP normal mode"))
      << "the watch never sampled in normal mode";
  const auto r = run_i20(eth(card), {"scan"});
  EXPECT_NE(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("another host is running the card"), std::string::npos) << r.err;
  kill(watch.pid, SIGINT);
  int status = 0;
  waitpid(watch.pid, &status, 0);
  close(watch.out_fd);
  close(watch.err_fd);
  EXPECT_EQ(run_i20(eth(card), {"scan"}).exit_code, 0) << "free again once the watch ended";
}

TEST(EthCli, TemperatureIsInTheManualsUnitsEndToEnd) {
  // INTERFACE0 LSW "Card Temperature in oC" (8I20 manual): whole degrees from the virtual
  // card, degrees on the screen.
  SimProcess card({"--temp", "47"}, Transport::Eth);
  const auto r = run_i20(eth(card), {"watch", "--count", "2", "--plain", "--interval", "30"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("TEMP 47.00 degC"), std::string::npos) << r.out;
}

TEST(EthCli, ControlFifoIsCreatedReadAndRemoved) {
  TempDir dir;
  const auto fifo = dir / "card.ctl";
  {
    SimProcess card({"--card", "7i92t", "--channels", "2", "--control", fifo.string()}, Transport::Eth);
    ASSERT_TRUE(appears(fifo)) << "the FIFO is created";
    EXPECT_TRUE(std::filesystem::is_fifo(fifo));
    write_line(fifo, "ch 1 busv 48");  // a writer does not block: the simulator holds the FIFO open
    EXPECT_TRUE(reads(card, "BUSV", "4800", 1));
    EXPECT_EQ(get_raw(card, "BUSV", 0), "BUSV = 32000\n") << "only channel 1 changed";
    write_line(fifo, "all enable off");
    for (unsigned ch : {0u, 1u}) {
      bool no_enable = false;
      for (int i = 0; i < 50 && !no_enable; ++i) {
        const auto out = get_raw(card, "FAULT", ch);  // "FAULT = N"
        no_enable = out.size() > 8 && (std::stoul(out.substr(8)) & 0x0002) != 0;
      }
      EXPECT_TRUE(no_enable) << "NOENABLEFAULT on ch " << ch;
    }
  }
  EXPECT_FALSE(std::filesystem::exists(fifo)) << "removed at exit: the simulator created it";
}

TEST(EthCli, ControlLinesAddressOneChannelOfSeveral) {
  SimProcess card({"--card", "7i92t", "--channels", "3"}, Transport::Eth);
  EXPECT_EQ(card.control("ch 2 busv 24"), "ok");
  EXPECT_EQ(card.control("channel 1 busv 100"), "ok");
  EXPECT_TRUE(reads(card, "BUSV", "2400", 2));
  EXPECT_TRUE(reads(card, "BUSV", "10000", 1));
  EXPECT_EQ(get_raw(card, "BUSV", 0), "BUSV = 32000\n");
  EXPECT_EQ(card.control("ch 2 get UNITNUMBER"), std::to_string(0x00012345 + 2));
  EXPECT_NE(card.control("ch 7 busv 1").find("error: no 8I20 on SSERIAL port 0 channel 7"),
            std::string::npos);
  EXPECT_EQ(card.control("amplifiers"), "8I20s on port 0 ch 0, port 0 ch 1, port 0 ch 2");
  const auto help = run("i20sim", {"--help"});
  EXPECT_NE(help.out.find("ch N LINE"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("host on"), std::string::npos) << help.out;
}

TEST(EthCli, ScanNamesEach8I20AsLinuxCncDoes) {
  SimProcess card({"--card", "7i92t", "--channels", "2"}, Transport::Eth);
  const auto r = run_i20(eth(card), {"scan"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("eth://" + card.port() + "/ch1  LinuxCNC hm2_7i92.0.8i20.0.1"), std::string::npos)
      << r.out;
  const auto j = run_i20(eth(card), {"--json", "scan"});
  EXPECT_NE(j.out.find("\"linuxcnc_name\": \"hm2_7i92.0.8i20.0.0\""), std::string::npos) << j.out;
}
