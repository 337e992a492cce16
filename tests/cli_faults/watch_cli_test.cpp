// SPDX-License-Identifier: GPL-2.0-or-later
// i20 watch as a process against i20sim --pty: plain output, CSV, JSON lines, live fault
// changes, and surviving a power cycle, a reset, a power loss and an unplugged adapter.
// Every wait is for a line to appear (generous deadline), never for a fixed time.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "harness.hpp"
#include "spawn.hpp"

using namespace i20::test;

namespace {

constexpr auto npos = std::string::npos;

bool has(const std::string& text, const std::string& needle) {
  return text.find(needle) != npos;
}

std::size_t count(const std::string& text, const std::string& needle) {
  std::size_t n = 0;
  for (auto at = text.find(needle); at != npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Splits one CSV row, honouring quoted fields.
std::vector<std::string> csv_fields(const std::string& row) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (std::size_t i = 0; i < row.size(); ++i) {
    const char c = row[i];
    if (c == '"' && quoted && i + 1 < row.size() && row[i + 1] == '"') {
      out.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

const char* kCsvHeader =
    "time,elapsed_s,busv_v,temperature_c,brake_on,status,fault,faultmask,fault_output_on,fault_bits,"
    "status_bits,events";

class WatchCli : public ::testing::Test {
 protected:
  std::vector<std::string> args(const std::string& port, std::vector<std::string> extra) {
    std::vector<std::string> a{"--port", port, "--no-user-params", "watch", "--interval", "50"};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
  Result watch(std::vector<std::string> extra) {
    return run("i20", args(sim.port(), std::move(extra)), {}, 60);
  }
  std::unique_ptr<Spawned> spawn(std::vector<std::string> extra) {
    return std::make_unique<Spawned>("i20", args(sim.port(), std::move(extra)));
  }
  SimProcess sim;
  TempDir dir;
};

}  // namespace

TEST_F(WatchCli, CountPrintsOneLinePerSampleAndASummary) {
  const auto r = watch({"--count", "3", "--plain"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "watching the 8I20 on " + sim.port() + " every 50 ms; Ctrl-C stops")) << r.out;
  EXPECT_EQ(
      count(r.out, "  BUSV 320.00 V  TEMP 35.00 degC  brake off  STATUS 0x0040  FAULT 0x0000  output ON"), 3u)
      << r.out;
  EXPECT_TRUE(has(r.out, "watch: 3 samples in")) << r.out;
  EXPECT_FALSE(has(r.out, "\x1b[")) << "no ANSI codes in plain output";
  // stdout is a pipe here: plain output without asking.
  const auto piped = watch({"--count", "2"});
  EXPECT_FALSE(has(piped.out, "\x1b[")) << piped.out;
  EXPECT_TRUE(has(piped.out, "watch: 2 samples in")) << piped.out;
}

TEST_F(WatchCli, StartingWithFaultsListsThemWithWhatToCheck) {
  sim.control("busv 24");
  const auto r = watch({"--count", "1", "--plain"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "FAULT 0x0100  output OFF")) << r.out;
  EXPECT_TRUE(has(r.out, "* FAULT set: BUSLOVFAULT (bit 8): Low motor voltage")) << r.out;
  EXPECT_TRUE(has(r.out, "; check: Measure the motor supply at spade terminals 4 (+) and 5 (-)")) << r.out;
}

TEST_F(WatchCli, CsvLogHasAHeaderAndOneRowPerSample) {
  const auto csv = dir / "series.csv";
  const auto r = watch({"--count", "4", "--log", csv.string()});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto rows = lines_of(slurp(csv));
  ASSERT_EQ(rows.size(), 5u) << slurp(csv);
  EXPECT_EQ(rows[0], kCsvHeader);
  const auto columns = csv_fields(rows[0]).size();
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto f = csv_fields(rows[i]);
    ASSERT_EQ(f.size(), columns) << rows[i];
    EXPECT_EQ(f[2], "320.00");
    EXPECT_EQ(f[3], "35.00");
    EXPECT_EQ(f[4], "0");
    EXPECT_EQ(f[5], "0x0040");
    EXPECT_EQ(f[6], "0x0000");
    EXPECT_EQ(f[7], "0xFFFF");
    EXPECT_EQ(f[8], "1");
    EXPECT_EQ(f[10], "EXTR");
    EXPECT_EQ(f[0].size(), 23u) << "ISO 8601 with milliseconds: " << f[0];
  }
}

TEST_F(WatchCli, JsonLinesOnePerSample) {
  const auto r = run("i20", {"--port", sim.port(), "--no-user-params", "--json", "watch", "--count", "2",
                             "--interval", "50"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto lines = lines_of(r.out);
  ASSERT_EQ(lines.size(), 4u) << r.out;
  EXPECT_TRUE(has(lines[0], "\"type\":\"start\"")) << lines[0];
  for (int i : {1, 2}) {
    EXPECT_TRUE(has(lines[i], "\"type\":\"sample\"")) << lines[i];
    EXPECT_TRUE(has(lines[i], "\"fault\":0")) << lines[i];
    EXPECT_TRUE(has(lines[i], "\"status\":64")) << lines[i];
    EXPECT_TRUE(has(lines[i], "\"busv_v\":320")) << lines[i];
  }
  EXPECT_TRUE(has(lines[3], "\"type\":\"summary\",\"samples\":2")) << lines[3];
}

TEST_F(WatchCli, BadOptionsAreBadInputAndSendNothing) {
  const auto before = sim.commands_seen();
  EXPECT_EQ(watch({"--interval", "0"}).exit_code, 2);
  EXPECT_EQ(watch({"--count", "0"}).exit_code, 2);
  const auto r = watch({"--count", "1", "--log", (dir / "missing" / "x.csv").string()});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(has(r.err, "cannot write the log file")) << r.err;
  EXPECT_EQ(sim.commands_seen(), before);
}

TEST_F(WatchCli, NoCardAtTheStartIsAnError) {
  const auto r =
      run("i20", {"--port", (dir / "ttyNothing").string(), "--no-user-params", "watch", "--count", "1"});
  EXPECT_EQ(r.exit_code, 1) << r.out;
  EXPECT_TRUE(has(r.err, "i20: error:")) << r.err;
}

TEST_F(WatchCli, DurationStopsTheWatch) {
  const auto r = watch({"--duration", "0.5"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(has(r.out, "watch: ")) << r.out;
}

TEST_F(WatchCli, FaultChangesAreTimestampedExplainedAndLogged) {
  const auto csv = dir / "faults.csv";
  auto w = spawn({"--plain", "--log", csv.string()});
  ASSERT_NE(w->wait_for("  BUSV "), npos) << w->err();
  sim.control("enable off");
  const auto set = w->wait_for("* FAULT set: NOENABLEFAULT (bit 1)");
  ASSERT_NE(set, npos) << w->out();
  EXPECT_NE(w->wait_for("; check: Measure between TB1 pin 3 (+) and pin 4 (-)", set), npos);
  EXPECT_NE(w->wait_for("* fault output OFF", set), npos);
  EXPECT_NE(w->wait_for("FAULT 0x0002*", 0), npos) << "the changed value is marked";
  sim.control("enable on");
  sim.control("set CLEARFAULT 1");  // what clear-faults writes; the watch holds the port
  EXPECT_NE(w->wait_for("* FAULT cleared: NOENABLEFAULT (bit 1)", set), npos) << w->out();
  const auto r = w->finish(SIGINT);  // Ctrl-C
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_TRUE(has(r.out, "2 FAULT changes")) << r.out;
  const std::string log = slurp(csv);
  EXPECT_TRUE(has(log, ",0x0002,0xFFFF,0,NOENABLEFAULT,")) << log;
  EXPECT_TRUE(has(log, "FAULT set: NOENABLEFAULT (bit 1)")) << log;
  EXPECT_TRUE(has(log, "FAULT cleared: NOENABLEFAULT (bit 1)")) << log;
}

TEST_F(WatchCli, SurvivesAPowerCycleAndSaysTheCardRestarted) {
  // Clear the power-up EXTR bit first, so the restart shows as EXTR rising again.
  ASSERT_EQ(run("i20", {"--port", sim.port(), "--no-user-params", "clear-faults"}).exit_code, 0);
  sim.control("busv 24");  // a fault, to see the restart keep it
  auto w = spawn({"--plain"});
  ASSERT_NE(w->wait_for("  BUSV "), npos) << w->err();
  sim.control("power cycle");
  const auto restarted = w->wait_for("* 8I20 restarted (EXTR rose)");
  ASSERT_NE(restarted, npos) << w->out();
  EXPECT_NE(w->wait_for("reconnecting to re-identify it", restarted), npos);
  EXPECT_NE(w->wait_for("  BUSV 24.00 V", restarted + 1), npos) << "it keeps watching: " << w->out();
  const auto r = w->finish(SIGINT);
  EXPECT_EQ(r.exit_code, 130) << r.err;
}

TEST_F(WatchCli, SurvivesAResetInTheMiddleOfABatch) {
  ASSERT_EQ(run("i20", {"--port", sim.port(), "--no-user-params", "clear-faults"}).exit_code, 0);
  auto w = spawn({"--plain"});
  ASSERT_NE(w->wait_for("  BUSV "), npos) << w->err();
  sim.control("reset-after 3");  // the DSP watchdog resets the card mid-batch
  const auto restarted = w->wait_for("* 8I20 restarted (WDTO rose)");
  ASSERT_NE(restarted, npos) << w->out();
  EXPECT_NE(w->wait_for("  BUSV 320.00 V", restarted), npos) << w->out();
  const auto r = w->finish(SIGINT);
  EXPECT_EQ(r.exit_code, 130) << r.err;
}

TEST_F(WatchCli, SurvivesLogicPowerLossAndReconnects) {
  const auto csv = dir / "gap.csv";
  auto w = spawn({"--plain", "--log", csv.string()});
  ASSERT_NE(w->wait_for("  BUSV "), npos) << w->err();
  sim.control("power off");
  const auto lost = w->wait_for("* lost contact with the 8I20 on " + sim.port());
  ASSERT_NE(lost, npos) << w->out();
  EXPECT_NE(w->wait_for("(Ctrl-C stops)", lost), npos);
  sim.control("power on");
  const auto back = w->wait_for("* reconnected to the 8I20 on " + sim.port() + " after ", lost);
  ASSERT_NE(back, npos) << w->out();
  const auto r = w->finish(SIGINT);
  EXPECT_EQ(r.exit_code, 130) << r.err;
  EXPECT_TRUE(has(r.out, ", 1 reconnect\n")) << r.out;
  const std::string log = slurp(csv);
  EXPECT_TRUE(has(log, ",,,,,,,,,,\"lost contact with the 8I20")) << "a gap row: " << log;
  EXPECT_TRUE(has(log, "reconnected to the 8I20")) << log;
}

TEST_F(WatchCli, SurvivesTheAdapterBeingUnpluggedAndReplugged) {
  // The "adapter" is a symlink to a simulator's pty: removing the simulator unplugs it,
  // a new simulator behind the same name plugs it back in.
  const auto port = dir / "ttyUSB-i20";
  std::filesystem::create_symlink(sim.port(), port);
  auto first = std::make_unique<SimProcess>();
  std::filesystem::remove(port);
  std::filesystem::create_symlink(first->port(), port);
  auto w = std::make_unique<Spawned>("i20", args(port.string(), {"--plain"}));
  ASSERT_NE(w->wait_for("  BUSV "), npos) << w->err();
  first.reset();  // unplugged
  const auto lost = w->wait_for("* lost contact with the 8I20 on " + port.string());
  ASSERT_NE(lost, npos) << w->out();
  SimProcess second;  // plugged back in
  std::filesystem::remove(port);
  std::filesystem::create_symlink(second.port(), port);
  const auto back = w->wait_for("* reconnected to the 8I20 on " + port.string(), lost);
  ASSERT_NE(back, npos) << w->out();
  EXPECT_NE(w->wait_for("  BUSV 320.00 V", back), npos);
  const auto r = w->finish(SIGINT);
  EXPECT_EQ(r.exit_code, 130) << r.err;
}
