// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 33 item 7: when no 8I20 answers, the message names what is really on the port
// instead of blaming W6, power or the cable: a loopback plug (every byte comes back) and a
// second program that has the port open (it may be reading the card's replies).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <deque>
#include <fstream>

#include "lbp/command.hpp"
#include "link/link.hpp"
#include "link/pipelined_link.hpp"
#include "link/ports.hpp"
#include "pty.hpp"

using namespace i20;
using namespace std::chrono_literals;

namespace {

// A port with a loopback plug: what is written is read back, byte for byte.
class EchoStream : public link::ByteStream {
 public:
  void write(lbp::ByteView bytes) override { pending_.insert(pending_.end(), bytes.begin(), bytes.end()); }
  std::size_t read_some(std::span<lbp::Byte> buffer, link::Clock::time_point deadline) override {
    if (pending_.empty()) {
      std::this_thread::sleep_until(std::min(deadline, link::Clock::now() + 5ms));
      return 0;
    }
    std::size_t n = 0;
    for (; n < buffer.size() && !pending_.empty(); ++n) {
      buffer[n] = pending_.front();
      pending_.pop_front();
    }
    return n;
  }
  void discard_input() override { pending_.clear(); }
  unsigned baud() const override { return 115200; }
  std::string name() const override { return "/dev/loopback0"; }

 private:
  std::deque<lbp::Byte> pending_;
};

bool child_of(pid_t pid) {
  return pid == 0;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

TEST(WrongWiring, ALoopbackPlugIsNamedNotBlamedOnTermination) {
  link::PipelinedLink link(
      std::make_unique<EchoStream>(),
      {.base_timeout = 50ms, .retries = 0u, .max_drain = std::chrono::milliseconds(500)});
  const std::vector<lbp::Command> batch = {lbp::read(0x0100, lbp::DataSize::Two),
                                           lbp::read(0x0102, lbp::DataSize::Two)};
  const std::string message = message_of([&] { link.execute(batch); });
  EXPECT_NE(message.find("loopback"), std::string::npos) << message;
  EXPECT_NE(message.find("sends back exactly what the tool writes"), std::string::npos) << message;
  EXPECT_EQ(message.find("termination"), std::string::npos) << message;
}

// A program that opened the adapter (a terminal program, `cat`) takes the replies: the
// silence is blamed on it, by name and PID, not on jumpers or wiring.
TEST(WrongWiring, ASecondProgramWithThePortOpenIsNamed) {
  link::fake::Pty pty;  // this process holds the master: the far end, as a simulator does
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t holder = ::fork();
  if (child_of(holder)) {
    ::close(pty.master());  // a plain reader of the port, like `cat /dev/ttyUSB0`
    const int fd = ::open(pty.slave_path().c_str(), O_RDONLY | O_NOCTTY);
    [[maybe_unused]] auto n = ::write(ready[1], fd >= 0 ? "y" : "n", 1);
    ::pause();
    ::_exit(0);
  }
  char opened = 0;
  ASSERT_EQ(::read(ready[0], &opened, 1), 1);
  ASSERT_EQ(opened, 'y');
  std::string comm;
  std::getline(std::ifstream("/proc/self/comm"), comm);
  const auto others = link::other_programs_with(pty.slave_path());
  ::kill(holder, SIGKILL);
  ::waitpid(holder, nullptr, 0);
  ASSERT_EQ(others.size(), 1u) << "the far end (holding the master) is not blamed, the reader is";
  EXPECT_EQ(others.front(), comm + " (PID " + std::to_string(holder) + ")");
  EXPECT_TRUE(link::other_programs_with(pty.slave_path()).empty()) << "gone with the reader";
  EXPECT_TRUE(link::other_programs_with("/no/such/device").empty());
}
