// SPDX-License-Identifier: GPL-2.0-or-later
// Stop requests sent to the programs as processes while they write a card served by
// `i20sim --pty`: SIGINT, SIGTERM and SIGHUP, one or two, before the first write, in the
// middle of one and during the restore; a stdout whose reader went away; kill -9 and the
// next command's recovery. Every verdict is the simulator's: its `show` line (NV access and
// RPC memory modes), its EEPROM image file and its trace of the commands it executed, never
// the tool's own report. Each moment is reached by waiting on the simulator's state (the
// first data write in its trace, NV access mode in `show`), never by sleeping.
//
// The card answers every command 50 ms late (`delay 50`), like a slow line, so that each
// moment lasts several of the tool's exchanges.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <fstream>
#include <functional>
#include <iterator>
#include <thread>

#include "eventually.hpp"
#include "harness.hpp"

using namespace i20::test;
using namespace std::chrono_literals;

namespace {

constexpr auto kPatience = 20s;  // a loaded 2-core machine; the conditions usually hold in ~1 s

bool has(const std::string& text, const std::string& needle) {
  return text.find(needle) != std::string::npos;
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// A program running in the background: signals can be sent to it, and its stdout reader can
// go away, while the test watches the simulator.
class Tool {
 public:
  Tool(const std::string& name, const std::vector<std::string>& args) {
    const Child c = start(name, args);
    pid_ = c.pid, out_ = c.out_fd, err_ = c.err_fd;
  }
  ~Tool() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    for (int fd : {out_, err_})
      if (fd >= 0) ::close(fd);
  }
  Tool(const Tool&) = delete;
  Tool& operator=(const Tool&) = delete;

  void signal(int sig) const { ::kill(pid_, sig); }
  // Sends `sig`, then waits until the process has taken it (no longer pending in
  // /proc/PID/status), so that a second one is a second delivery, not merged into the first.
  bool signal_delivered(int sig) const {
    signal(sig);
    const std::uint64_t bit = std::uint64_t{1} << (sig - 1);
    return eventually(
        [&] {
          std::ifstream status("/proc/" + std::to_string(pid_) + "/status");
          std::uint64_t pending = 0;
          for (std::string line; std::getline(status, line);)
            if (line.rfind("SigPnd:", 0) == 0 || line.rfind("ShdPnd:", 0) == 0)
              pending |= std::stoull(line.substr(7), nullptr, 16);
          return (pending & bit) == 0;
        },
        kPatience);
  }
  int killed_by() const { return killed_by_; }  // the signal that ended it, 0 if it exited
  // The reader of stdout exits (`i20 ... | head -1` after its line): later writes fail.
  void close_stdout_reader() {
    ::close(out_);
    out_ = -1;
  }
  // Runs to the end (killed after kPatience). exit_code is 128 + N when signal N ended it
  // (so 130 for SIGINT: killed_by() tells a death by the signal from a report).
  Result wait() {
    if (pid_ <= 0) return result_;
    const auto deadline = std::chrono::steady_clock::now() + kPatience;
    while (pump() && std::chrono::steady_clock::now() < deadline) {
    }
    if (std::chrono::steady_clock::now() >= deadline) ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    result_.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    killed_by_ = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    return result_;
  }
  // Reads what is there (both pipes), so the tool never blocks on a full pipe.
  bool pump() {
    pollfd fds[2] = {{out_, POLLIN, 0}, {err_, POLLIN, 0}};
    if (out_ < 0 && err_ < 0) return false;
    if (::poll(fds, 2, 20) <= 0) return true;
    int* fd[2] = {&out_, &err_};
    std::string* sink[2] = {&result_.out, &result_.err};
    for (int i = 0; i < 2; ++i) {
      if (*fd[i] < 0 || !(fds[i].revents & (POLLIN | POLLHUP))) continue;
      char buf[4096];
      const auto n = ::read(*fd[i], buf, sizeof buf);
      if (n > 0) {
        sink[i]->append(buf, static_cast<std::size_t>(n));
      } else {
        ::close(*fd[i]);
        *fd[i] = -1;
      }
    }
    return out_ >= 0 || err_ >= 0;
  }

 private:
  int pid_ = -1;
  int out_ = -1;
  int err_ = -1;
  int killed_by_ = 0;
  Result result_;
};

// Three EEPROM cells that differ from the defaults (KQP = KDP, as the rules want).
constexpr const char* kProfile =
    "schema: 1\nname: signals\nparameters:\n  NVKQP: 80\n  NVKDP: 80\n  NVMAXCURRENT: 12 A\n";

class Signals : public ::testing::Test {
 protected:
  Signals() : sim({"--eeprom", (dir / "card.eeprom").string()}) {
    std::ofstream(dir / "motor.yaml") << kProfile;
    original = slurp(dir / "card.eeprom");
    EXPECT_EQ(sim.control("delay 50"), "ok");
  }

  std::vector<std::string> apply_args() const {
    return {"--port",
            sim.port(),
            "--no-user-params",
            "--timeout",
            "3000",
            "profile",
            "apply",
            (dir / "motor.yaml").string(),
            "--yes",
            "--backup-dir",
            (dir / "backups").string()};
  }
  std::string show() { return sim.control("show"); }
  bool settled() {
    const auto s = show();
    return has(s, "nv_access=ram") && has(s, "rpcmem=off");
  }
  std::string eeprom() const { return slurp(dir / "card.eeprom"); }
  bool first_command_seen() const { return sim.commands_seen() > 0; }
  bool writes_seen(std::size_t n) const { return sim.writes_seen() >= n; }

  // Waits on the simulator while pumping the tool's pipes.
  bool until(Tool& tool, const std::function<bool()>& condition) {
    return eventually(
        [&] {
          tool.pump();
          return condition();
        },
        kPatience);
  }

  // The verdict after a stop in the middle of the change: the EEPROM image is the one the
  // card had before, both modes are off, the tool wrote (and so restored) and exited 130.
  void expect_restored(Tool& tool) {
    const Result r = tool.wait();
    EXPECT_EQ(tool.killed_by(), 0) << "the signal ended the process instead of a report";
    EXPECT_EQ(r.exit_code, 130) << r.out << r.err;
    EXPECT_TRUE(settled()) << show();
    EXPECT_TRUE(eeprom() == original) << "the EEPROM image differs from the one before the apply";
    EXPECT_GE(sim.writes_seen(), 2u) << "expected a write and its restore";
  }

  TempDir dir;
  SimProcess sim;
  std::string original;
};

// ------------------------------------------------------------------ before the first write
class EverySignal : public Signals, public ::testing::WithParamInterface<int> {};

TEST_P(EverySignal, BeforeTheFirstWriteNothingIsWritten) {
  Tool tool("i20", apply_args());
  ASSERT_TRUE(until(tool, [&] { return first_command_seen(); }));
  ASSERT_EQ(sim.writes_seen(), 0u) << "the card was written before the test could stop it";
  tool.signal(GetParam());
  const auto r = tool.wait();
  EXPECT_EQ(tool.killed_by(), 0) << "the signal ended the process instead of a report";
  EXPECT_EQ(r.exit_code, 130) << r.out << r.err;
  EXPECT_EQ(sim.writes_seen(), 0u);
  EXPECT_TRUE(settled()) << show();
  EXPECT_TRUE(eeprom() == original);
}

// ------------------------------------------------------------------ in the middle of a write
TEST_P(EverySignal, MidWriteStopsRestoresAndSettles) {
  Tool tool("i20", apply_args());
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1); }));
  tool.signal(GetParam());
  expect_restored(tool);
}

TEST_P(EverySignal, TwoInARowMidWriteEndTheSameWay) {
  Tool tool("i20", apply_args());
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1); }));
  ASSERT_TRUE(tool.signal_delivered(GetParam()));
  tool.signal(GetParam());  // the "two SIGINTs 10 ms apart": a second delivery
  expect_restored(tool);
}

INSTANTIATE_TEST_SUITE_P(
    Signals, EverySignal, ::testing::Values(SIGINT, SIGTERM, SIGHUP), [](const auto& info) {
      return std::string(info.param == SIGINT ? "SIGINT" : info.param == SIGTERM ? "SIGTERM" : "SIGHUP");
    });

// ------------------------------------------------------------------ during the restore
TEST_F(Signals, ASignalDuringTheRestoreIsAcknowledgedAndDoesNotEndIt) {
  Tool tool("i20", apply_args());
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1); }));
  tool.signal(SIGINT);
  // The tool stops before its second write, so the next data write is the restore.
  ASSERT_TRUE(until(tool, [&] { return writes_seen(2); }));
  tool.signal(SIGINT);
  tool.signal(SIGTERM);
  expect_restored(tool);
  EXPECT_TRUE(has(tool.wait().err, "the card settles in a moment"));
}

// ------------------------------------------------------------------ wpd, one cell
TEST_F(Signals, WpdStoppedDuringItsOnlyWriteRestoresIt) {
  Tool tool("wpd", {"--port", sim.port(), "--no-user-params", "--timeout", "3000", "NVMAXCURRENT", "1234"});
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1); }));
  tool.signal(SIGTERM);
  expect_restored(tool);
}

// ------------------------------------------------------------------ a closed stdout
TEST_F(Signals, AStdoutWhoseReaderWentAwayDoesNotStopTheWrite) {
  Tool tool("i20", apply_args());
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1); }));
  tool.close_stdout_reader();  // every progress line after this fails with EPIPE
  const auto r = tool.wait();
  EXPECT_EQ(tool.killed_by(), 0) << "the signal ended the process instead of a report";
  // Not 141: SIGPIPE did not end it, the apply is done; but its report did not land, which
  // is not a success (exit 6, issue 33).
  EXPECT_EQ(r.exit_code, 6) << r.err;
  EXPECT_TRUE(settled()) << show();
  EXPECT_EQ(sim.control("get NVKQP"), "80");
  EXPECT_EQ(sim.control("get NVMAXCURRENT"), "1200");
  EXPECT_TRUE(has(r.err, "standard output was not written in full")) << r.err;
}

// ------------------------------------------------------------------ kill -9 and the next command
TEST_F(Signals, AfterKill9TheNextCommandSettlesTheCard) {
  Tool tool("i20", apply_args());
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1) && has(show(), "nv_access=eeprom"); }));
  tool.signal(SIGKILL);  // cannot be caught: the card stays in NV access mode
  EXPECT_EQ(tool.wait().exit_code, 128 + SIGKILL);
  ASSERT_TRUE(has(show(), "nv_access=eeprom")) << show();
  const auto next = run("i20", {"--port", sim.port(), "--no-user-params", "--timeout", "3000", "info"});
  EXPECT_EQ(next.exit_code, 0) << next.err;
  EXPECT_TRUE(settled()) << show();
  EXPECT_TRUE(has(next.out, "left in NV access mode by an earlier session")) << next.out;
}

// ------------------------------------------------------------------ a fleet of two cards
TEST_F(Signals, AFleetStoppedMidWriteLeavesEveryCardAsItWas) {
  SimProcess second({"--eeprom", (dir / "second.eeprom").string()});
  ASSERT_EQ(second.control("delay 50"), "ok");
  const auto second_before = slurp(dir / "second.eeprom");
  Tool tool("i20", {"--no-user-params", "--timeout", "3000", "profile", "apply",
                    (dir / "motor.yaml").string(), "--target", sim.port(), "--target", second.port(), "--yes",
                    "--backup-dir", (dir / "backups").string()});
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1) || second.writes_seen() >= 1; }));
  tool.signal(SIGHUP);
  const auto r = tool.wait();
  EXPECT_EQ(tool.killed_by(), 0) << "the signal ended the process instead of a report";
  EXPECT_EQ(r.exit_code, 130) << r.out << r.err;
  EXPECT_TRUE(settled()) << show();
  const auto s2 = second.control("show");
  EXPECT_TRUE(has(s2, "nv_access=ram") && has(s2, "rpcmem=off")) << s2;
  EXPECT_TRUE(eeprom() == original);
  EXPECT_TRUE(slurp(dir / "second.eeprom") == second_before);
}

// ------------------------------------------------------------------ the other long-running commands
TEST_F(Signals, DiscoverStopsOnSigtermWithTheCardSettled) {
  Tool tool("i20", {"--port", sim.port(), "--no-user-params", "--timeout", "3000", "discover", "--yes", "-o",
                    (dir / "map.yaml").string()});
  ASSERT_TRUE(until(tool, [&] { return sim.commands_seen() > 40; }));
  tool.signal(SIGTERM);
  const auto r = tool.wait();
  EXPECT_EQ(tool.killed_by(), 0) << "the signal ended the process instead of a report";
  EXPECT_EQ(r.exit_code, 130) << r.out << r.err;
  EXPECT_TRUE(settled()) << show();
  EXPECT_FALSE(std::filesystem::exists(dir / "map.yaml"));
}

TEST_F(Signals, ClearFaultsStopsOnSighupWithTheCardSettled) {
  ASSERT_EQ(sim.control("delay 0"), "ok");
  ASSERT_EQ(sim.control("clearfault-stuck on"), "ok");
  ASSERT_EQ(sim.control("enable off"), "ok");  // a fault to clear
  Tool tool("i20", {"--port", sim.port(), "--no-user-params", "clear-faults"});
  ASSERT_TRUE(until(tool, [&] { return writes_seen(1); }));  // CLEARFAULT written, never returns to 0
  tool.signal(SIGHUP);
  const auto r = tool.wait();
  EXPECT_EQ(tool.killed_by(), 0) << "the signal ended the process instead of a report";
  EXPECT_EQ(r.exit_code, 130) << r.out << r.err;
  EXPECT_TRUE(settled()) << show();
}

TEST_F(Signals, WatchEndsOnSigtermWithExit130) {
  ASSERT_EQ(sim.control("delay 0"), "ok");
  Tool tool("i20", {"--port", sim.port(), "--no-user-params", "watch", "--plain"});
  ASSERT_TRUE(until(tool, [&] { return sim.commands_seen() > 30; }));
  tool.signal(SIGTERM);
  const auto r = tool.wait();
  EXPECT_EQ(tool.killed_by(), 0) << "the signal ended the process instead of a report";
  EXPECT_EQ(r.exit_code, 130) << r.out << r.err;
  EXPECT_TRUE(settled()) << show();
}

}  // namespace
