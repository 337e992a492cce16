// SPDX-License-Identifier: GPL-2.0-or-later
// End to end: build/bin/i20sim --pty serves a pseudo-terminal that behaves like the
// card's serial port. The test spawns it, reads the path, talks raw LBP bytes, drives
// the world through stdin, and stops it with SIGTERM.
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench.hpp"
#include "build_paths.hpp"
#include "lbp/command.hpp"
#include "link/serial_link.hpp"

namespace i20::sim::test {
namespace {

std::string bin_dir() {
  const char* dir = std::getenv("I20_BIN_DIR");
  return dir && *dir ? std::string(dir) : i20::test::bin_dir().string();
}

// i20sim as a child process with pipes on stdin and stdout.
class Child {
 public:
  explicit Child(std::vector<std::string> args) {
    int in[2], out[2];
    if (::pipe(in) != 0 || ::pipe(out) != 0) throw std::runtime_error("pipe");
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(in[0], STDIN_FILENO);
      ::dup2(out[1], STDOUT_FILENO);
      ::close(in[1]);
      ::close(out[0]);
      std::vector<char*> argv;
      const std::string exe = bin_dir() + "/i20sim";
      argv.push_back(const_cast<char*>(exe.c_str()));
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(exe.c_str(), argv.data());
      ::_exit(127);
    }
    ::close(in[0]);
    ::close(out[1]);
    stdin_ = in[1];
    stdout_ = out[0];
  }
  ~Child() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    ::close(stdin_);
    ::close(stdout_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // One line of the child's stdout, "" on timeout or end of file.
  std::string line(int timeout_ms = 5000) {
    std::string out;
    for (;;) {
      pollfd p{stdout_, POLLIN, 0};
      if (::poll(&p, 1, timeout_ms) <= 0) return out;
      char c;
      if (::read(stdout_, &c, 1) != 1) return out;
      if (c == '\n') return out;
      out += c;
    }
  }
  // Everything the child writes to stdout until it closes it.
  std::string rest() {
    std::string out;
    char buf[4096];
    for (ssize_t n; (n = ::read(stdout_, buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
    return out;
  }
  void say(const std::string& text) {
    ASSERT_EQ(::write(stdin_, text.data(), text.size()), ssize_t(text.size()));
  }
  // Sends SIGTERM and returns the exit status (or -1).
  int terminate() {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  int wait_exit() {
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  int stdin_ = -1, stdout_ = -1;
};

// The client side of the pty, set up the way a serial tool would (raw 115200 8N1).
class Port {
 public:
  // `configure`: set raw 115200 8N1 as a serial tool would; without it the pty's own
  // settings (raw, set by i20sim) must already pass every byte untouched.
  explicit Port(const std::string& path, bool configure = true)
      : fd_(::open(path.c_str(), O_RDWR | O_NOCTTY)) {
    if (fd_ < 0 || !configure) return;
    termios tio{};
    ::tcgetattr(fd_, &tio);
    ::cfmakeraw(&tio);
    ::cfsetspeed(&tio, B115200);
    ::tcsetattr(fd_, TCSANOW, &tio);
  }
  ~Port() {
    if (fd_ >= 0) ::close(fd_);
  }
  Port(const Port&) = delete;
  Port& operator=(const Port&) = delete;
  bool ok() const { return fd_ >= 0; }

  lbp::Bytes exchange(const lbp::Bytes& wire, std::size_t expect, int timeout_ms = 3000) {
    EXPECT_EQ(::write(fd_, wire.data(), wire.size()), ssize_t(wire.size()));
    lbp::Bytes out;
    while (out.size() < expect) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, timeout_ms) <= 0) break;
      lbp::Byte buf[64];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) break;
      out.insert(out.end(), buf, buf + n);
    }
    return out;
  }

 private:
  int fd_;
};

TEST(SimPty, ServesRawLbpAndStopsCleanly) {
  Child sim({"--pty"});
  const std::string path = sim.line();
  ASSERT_EQ(path.rfind("/dev/pts/", 0), 0u)
      << "first line must be the slave path alone, got '" << path << "'";
  {
    Port port(path);
    ASSERT_TRUE(port.ok());
    EXPECT_EQ(port.exchange(framed("DF"), 2), reply("5A"));
    EXPECT_EQ(port.exchange(cat({framed("D0"), framed("D1"), framed("D2"), framed("D3")}), 8),
              cat({reply("38"), reply("49"), reply("32"), reply("30")}));
    EXPECT_EQ(port.exchange(framed("45 74 08"), 3), reply("20 E1"));
  }
  // A client that disconnects does not hang the pty up: the next one is served too.
  {
    Port again(path);
    ASSERT_TRUE(again.ok());
    EXPECT_EQ(again.exchange(framed("DF"), 2), reply("5A"));
  }
  EXPECT_EQ(sim.terminate(), 0);
}

TEST(SimPty, EveryByteValuePassesUntouched) {
  Child sim({"--pty"});
  Port port(sim.line(), /*configure=*/false);
  ASSERT_TRUE(port.ok());
  // CR, LF, XON, XOFF, ^C, ^D, 0xFF: what a cooked terminal would translate or swallow.
  EXPECT_EQ(port.exchange(framed("6F 00 30 0D 0A 11 13 03 04 7F FF"), 1), lbp::Bytes{0x00});
  EXPECT_EQ(port.exchange(framed("47 00 30"), 9), reply("0D 0A 11 13 03 04 7F FF"));
  EXPECT_EQ(sim.terminate(), 0);
}

TEST(SimPty, TheProjectsSerialLinkTalksToIt) {
  Child sim({"--pty"});
  const std::string path = sim.line();
  auto link = link::open_serial_link(
      path,
      {.base_timeout = std::chrono::milliseconds(50),
       .retries = 0u,
       .max_drain = std::chrono::milliseconds(500)},
      {.write_slack = std::chrono::milliseconds(2000), .cancel_grace = std::chrono::milliseconds(200)});
  const std::vector<lbp::Command> batch{lbp::local_read(lbp::local::kGetCookie),
                                        lbp::read(2164, lbp::DataSize::Two)};
  const auto replies = link->execute(batch);
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[0], lbp::Bytes{0x5A});
  EXPECT_EQ(replies[1], lbp::from_hex("20 E1"));
  EXPECT_EQ(sim.terminate(), 0);
}

TEST(SimPty, ControlLinesOnStdinChangeTheWorld) {
  Child sim({"--pty", "--busv", "48"});
  Port port(sim.line());
  ASSERT_TRUE(port.ok());
  EXPECT_EQ(port.exchange(framed("81"), 5), reply("C0 12 AC 0D"));  // 48 V, 35 C
  sim.say("busv 400.5\n");
  EXPECT_EQ(sim.line(), "ok");
  sim.say("bogus\n");
  EXPECT_NE(sim.line().find("error: unknown control command"), std::string::npos);
  sim.say("get BUSV\n");
  EXPECT_EQ(sim.line(), "40050");
  EXPECT_EQ(port.exchange(framed("81"), 5), reply("72 9C AC 0D"));
  sim.say("drop 1\n");
  EXPECT_EQ(sim.line(), "ok");
  EXPECT_TRUE(port.exchange(framed("DF"), 2, 300).empty());
  EXPECT_EQ(sim.terminate(), 0);
}

TEST(SimPty, EepromPersistsAcrossRuns) {
  const std::string file = "/tmp/i20sim-pty-" + std::to_string(::getpid()) + ".eeprom";
  ::unlink(file.c_str());
  {
    Child sim({"--pty", "--eeprom", file});
    Port port(sim.line());
    ASSERT_TRUE(port.ok());
    EXPECT_EQ(port.exchange(framed("EC 01"), 1), lbp::Bytes{0x00});
    EXPECT_EQ(port.exchange(framed("65 02 00 D0 07"), 1), lbp::Bytes{0x00});
    EXPECT_EQ(sim.terminate(), 0);
  }
  Child sim({"--pty", "--eeprom", file});
  Port port(sim.line());
  ASSERT_TRUE(port.ok());
  EXPECT_EQ(port.exchange(framed("45 E8 08"), 3), reply("D0 07"))
      << "MAXCURRENT (0x08E8) = NVMAXCURRENT 2000";
  EXPECT_EQ(sim.terminate(), 0);
  ::unlink(file.c_str());
}

TEST(SimPty, PrintMapAndHelp) {
  {
    Child sim({"--print-map", "--random-map", "5"});
    const std::string first = sim.line();
    EXPECT_EQ(first.rfind("SWREVISION 0x", 0), 0u) << first;
    EXPECT_NE(first, "SWREVISION 0xE120");
    EXPECT_EQ(sim.wait_exit(), 0);
  }
  {
    Child sim({"--help"});
    const std::string all = sim.rest();
    for (const char* opt : {"--pty", "--eeprom", "--random-map", "--wire-time", "--drop",
                            "--eeprom-power-loss", "--control", "busv VOLTS"})
      EXPECT_NE(all.find(opt), std::string::npos) << opt;
    EXPECT_EQ(sim.wait_exit(), 0);
  }
  {
    Child sim({});
    EXPECT_NE(sim.wait_exit(), 0) << "nothing to do is an error";
  }
}

TEST(SimPty, AddressMapFile) {
  const std::string good = "/tmp/i20sim-map-" + std::to_string(::getpid()) + ".map";
  const std::string bad = good + ".bad";
  {
    std::FILE* f = std::fopen(good.c_str(), "w");
    std::fputs("FAULT = 0x0900\nrevision = 0xE121\n", f);
    std::fclose(f);
    f = std::fopen(bad.c_str(), "w");
    std::fputs("FAULT = 0x0802\n", f);  // on top of STATUS
    std::fclose(f);
  }
  {
    Child sim({"--print-map", "--address-map", good});
    const std::string all = sim.rest();
    EXPECT_EQ(all.rfind("SWREVISION 0xE121\n", 0), 0u) << all;
    EXPECT_NE(all.find("0x0900 FAULT"), std::string::npos) << all;
    EXPECT_EQ(sim.wait_exit(), 0);
  }
  {
    Child sim({"--pty", "--address-map", bad});
    EXPECT_EQ(sim.line(), "") << "no pty path when the map is unusable";
    EXPECT_NE(sim.wait_exit(), 0);
  }
  ::unlink(good.c_str());
  ::unlink(bad.c_str());
}

TEST(SimPty, ControlFifo) {
  const std::string fifo = "/tmp/i20sim-ctl-" + std::to_string(::getpid());
  Child sim({"--pty", "--no-stdin", "--control", fifo});
  Port port(sim.line());
  ASSERT_TRUE(port.ok());
  {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    ASSERT_GE(fd, 0);
    const std::string cmd = "enable off\n";
    EXPECT_EQ(::write(fd, cmd.data(), cmd.size()), ssize_t(cmd.size()));
    ::close(fd);
  }
  EXPECT_EQ(sim.line(), "ok");
  EXPECT_EQ(port.exchange(framed("45 00 08"), 3), reply("02 00")) << "NOENABLEFAULT";
  EXPECT_EQ(sim.terminate(), 0);
  EXPECT_NE(::access(fifo.c_str(), F_OK), 0) << "the FIFO it created is removed";
}

}  // namespace
}  // namespace i20::sim::test
