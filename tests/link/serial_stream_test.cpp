// SPDX-License-Identifier: GPL-2.0-or-later
// SerialStream against a real pseudo-terminal pair, and PipelinedLink over it with a
// fake card doing real LBP framing on the far side.
#include "link/serial_stream.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include "eventually.hpp"
#include "lbp/command.hpp"
#include "link/serial_link.hpp"
#include "pty.hpp"

using namespace i20;
using namespace i20::link;
using namespace std::chrono_literals;
using fake::Pty;
using fake::PtyCard;
using fake::SlaveQueue;
using lbp::Bytes;
namespace fs = std::filesystem;

namespace {

// The serial port's own bounds, named here (the programs' are in ops/core/timing.hpp).
SerialOptions port_figures() {
  return {.write_slack = std::chrono::milliseconds(2000), .cancel_grace = std::chrono::milliseconds(200)};
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

// Reads until `count` bytes or two seconds have passed.
Bytes read_exactly(SerialStream& s, std::size_t count) {
  Bytes out;
  const auto deadline = Clock::now() + 2s;
  while (out.size() < count) {
    lbp::Byte buffer[64];
    const auto n = s.read_some(std::span(buffer, std::min(sizeof buffer, count - out.size())), deadline);
    if (n == 0) break;
    out.insert(out.end(), buffer, buffer + n);
  }
  return out;
}

class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "i20-link-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void write_file(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(SerialStream, OpensRaw8N1WithoutFlowControlAtTheRequestedBaud) {
  Pty pty;
  auto options = port_figures();
  options.baud = 57600;
  SerialStream stream(pty.slave_path(), options);
  EXPECT_EQ(stream.baud(), 57600u);
  EXPECT_EQ(stream.name(), pty.slave_path());
  termios t{};
  ASSERT_EQ(::tcgetattr(pty.master(), &t), 0);  // a master reports its slave's settings
  EXPECT_EQ(::cfgetospeed(&t), B57600);
  EXPECT_EQ(::cfgetispeed(&t), B57600);
  EXPECT_EQ(t.c_cflag & CSIZE, tcflag_t(CS8));
  EXPECT_FALSE(t.c_cflag & PARENB);
  EXPECT_FALSE(t.c_cflag & CSTOPB);
  EXPECT_FALSE(t.c_cflag & CRTSCTS);
  EXPECT_FALSE(t.c_iflag & (IXON | IXOFF | ICRNL | INLCR));
  EXPECT_FALSE(t.c_lflag & (ICANON | ECHO | ISIG));
  EXPECT_FALSE(t.c_oflag & OPOST);
}

TEST(SerialStream, DefaultsTo115200) {
  Pty pty;
  SerialStream stream(pty.slave_path(), port_figures());
  termios t{};
  ASSERT_EQ(::tcgetattr(pty.master(), &t), 0);
  EXPECT_EQ(::cfgetospeed(&t), B115200);
  EXPECT_EQ(stream.baud(), 115200u);
}

TEST(SerialStream, RoundTripsEveryByteValue) {
  Pty pty;
  SerialStream stream(pty.slave_path(), port_figures());
  Bytes all(256);
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<lbp::Byte>(i);
  stream.write(all);
  EXPECT_EQ(pty.receive(all.size(), 2000ms), all) << "raw: no CR/LF translation, no XON/XOFF";
  pty.send(all);
  EXPECT_EQ(read_exactly(stream, all.size()), all);
}

TEST(SerialStream, ReadReturnsNothingAtTheDeadline) {
  Pty pty;
  SerialStream stream(pty.slave_path(), port_figures());
  lbp::Byte buffer[8];
  const auto start = Clock::now();
  EXPECT_EQ(stream.read_some(buffer, start + 50ms), 0u);
  const auto elapsed = Clock::now() - start;
  EXPECT_GE(elapsed, 45ms);
  EXPECT_LT(elapsed, 2s);
  // Still usable afterwards.
  pty.send(Bytes{0x42});
  EXPECT_EQ(read_exactly(stream, 1), Bytes{0x42});
}

TEST(SerialStream, FarDeadlineReturnsAsSoonAsBytesArrive) {
  Pty pty;
  SerialStream stream(pty.slave_path(), port_figures());
  std::thread sender([&] {
    // The subject is timing: the byte comes while read_some() waits (had the read not started
    // yet, the test would still pass, only prove less). A head start, not an ordering.
    std::this_thread::sleep_for(100ms);
    pty.send(Bytes{7});
  });
  lbp::Byte buffer[8];
  const auto start = Clock::now();
  EXPECT_EQ(stream.read_some(buffer, Clock::time_point::max()), 1u);
  EXPECT_LT(Clock::now() - start, 2s);
  sender.join();
}

TEST(SerialStream, DeadlineInThePastStillReturnsBufferedBytes) {
  Pty pty;
  const SlaveQueue queue(pty);
  SerialStream stream(pty.slave_path(), port_figures());
  pty.send(Bytes{1, 2, 3});
  ASSERT_TRUE(i20::test::eventually([&] { return queue.queued() == 3; }))  // in the slave's queue
      << queue.queued() << " bytes arrived";
  lbp::Byte buffer[8];
  EXPECT_EQ(stream.read_some(buffer, Clock::now() - 1s), 3u);
  EXPECT_EQ(stream.read_some(buffer, Clock::now()), 0u);
}

TEST(SerialStream, DiscardInputDropsWhatArrivedBefore) {
  Pty pty;
  const SlaveQueue queue(pty);
  SerialStream stream(pty.slave_path(), port_figures());
  pty.send(Bytes{0xEE, 0xEE, 0xEE, 0xEE});
  ASSERT_TRUE(i20::test::eventually([&] { return queue.queued() == 4; }))  // arrived: before the discard
      << queue.queued() << " bytes arrived";
  stream.discard_input();
  pty.send(Bytes{0x11, 0x22});
  EXPECT_EQ(read_exactly(stream, 2), (Bytes{0x11, 0x22}));
  lbp::Byte buffer[8];
  EXPECT_EQ(stream.read_some(buffer, Clock::now() + 20ms), 0u);
}

TEST(SerialStream, OpenErrorsNameThePathAndTheFix) {
  try {
    SerialStream("/dev/ttyI20-no-such-port", port_figures());
    FAIL() << "opened a port that does not exist";
  } catch (const LinkError& e) {
    EXPECT_TRUE(contains(e.what(), "/dev/ttyI20-no-such-port")) << e.what();
    EXPECT_TRUE(contains(e.what(), "plugged in")) << e.what();
  }
  TempDir dir;
  const auto file = dir.path() / "not-a-tty";
  write_file(file, "x");
  try {
    SerialStream(file.string(), port_figures());
    FAIL() << "opened a regular file as a serial port";
  } catch (const LinkError& e) {
    EXPECT_TRUE(contains(e.what(), file.string())) << e.what();
    EXPECT_TRUE(contains(e.what(), "not a serial port")) << e.what();
  }
}

TEST(SerialStream, PermissionErrorPointsAtTheDialoutGroup) {
  if (::geteuid() == 0) GTEST_SKIP() << "root opens any device";
  Pty pty;
  ASSERT_EQ(::chmod(pty.slave_path().c_str(), 0), 0);
  try {
    SerialStream stream(pty.slave_path(), port_figures());
    FAIL() << "opened a port without permission";
  } catch (const LinkError& e) {
    EXPECT_TRUE(contains(e.what(), "dialout")) << e.what();
  }
}

TEST(SerialStream, ExclusiveAccessKeepsASecondOpenerOut) {
  Pty pty;
  SerialStream first(pty.slave_path(), port_figures());
  EXPECT_TRUE(contains(joined(first.notes()), "exclusive access")) << joined(first.notes());
  try {
    SerialStream second(pty.slave_path(), port_figures());
    if (::geteuid() == 0) GTEST_SKIP() << "root may open an exclusive tty";
    FAIL() << "a second program could open the port";
  } catch (const LinkError& e) {
    EXPECT_TRUE(contains(e.what(), "in use")) << e.what();
  }
}

// TIOCEXCL does not stop root, so every opener also takes an advisory lock: a second i20
// (root included, as here in CI) is refused and told which process holds the port, before
// it touches the line settings or sends a byte.
TEST(SerialStream, ASecondProgramIsRefusedEvenAsRootAndToldWhoHoldsThePort) {
  Pty pty;
  auto shared = port_figures();
  shared.exclusive = false;  // only the advisory lock stands between the two
  SerialStream first(pty.slave_path(), shared);
  try {
    SerialStream second(pty.slave_path(), shared);
    FAIL() << "two programs shared one adapter";
  } catch (const LinkError& e) {
    const std::string text = e.what();
    EXPECT_TRUE(contains(text, "is in use by PID " + std::to_string(::getpid()))) << text;
    EXPECT_TRUE(contains(text, "one program")) << text;
    EXPECT_EQ(text.find('\n'), std::string::npos) << "one line: " << text;
  }
}

TEST(SerialStream, TheLockGoesWithTheProgram) {
  Pty pty;
  { SerialStream first(pty.slave_path(), port_figures()); }
  EXPECT_NO_THROW(SerialStream again(pty.slave_path(), port_figures())) << "a closed port is free again";
}

TEST(SerialStream, NotesSayWhatLowLatencySetUpAchieved) {
  Pty pty;
  SerialStream stream(pty.slave_path(), port_figures());
  const auto notes = joined(stream.notes());
  EXPECT_TRUE(contains(notes, "low-latency mode:")) << notes;
  EXPECT_TRUE(contains(notes, "latency timer:")) << notes;
  auto quiet = port_figures();
  quiet.low_latency = false;
  quiet.exclusive = false;
  Pty pty2;
  EXPECT_TRUE(SerialStream(pty2.slave_path(), quiet).notes().empty());
}

TEST(SerialStream, LatencyTimerIsLoweredToOneMillisecond) {
  TempDir sys;
  const auto timer = sys.path() / "bus/usb-serial/devices/ttyUSB3/latency_timer";
  write_file(timer, "16\n");
  const auto note = tune_usb_latency_timer(sys.path(), "ttyUSB3");
  EXPECT_TRUE(contains(note, "set to 1 ms (was 16 ms)")) << note;
  EXPECT_EQ(read_file(timer), "1");
  EXPECT_TRUE(contains(tune_usb_latency_timer(sys.path(), "ttyUSB3"), "already 1 ms"));
}

TEST(SerialStream, LatencyTimerNotesSayWhyNot) {
  TempDir sys;
  EXPECT_TRUE(contains(tune_usb_latency_timer(sys.path(), "ttyACM0"), "not a usb-serial adapter"));
  // A timer that cannot be written (a directory fails even for root).
  fs::create_directories(sys.path() / "bus/usb-serial/devices/ttyUSB0/latency_timer");
  const auto note = tune_usb_latency_timer(sys.path(), "ttyUSB0");
  EXPECT_TRUE(contains(note, "cannot write")) << note;
  EXPECT_TRUE(contains(note, "udev")) << note;
}

TEST(SerialStream, CarriesPipelinedLbpToAFakeCard) {
  Pty pty;
  PtyCard card(pty);
  // Each batch sent once, 500 ms for a reply: slow CI machines; a real card answers in microseconds.
  const PipelinedLinkOptions options{
      .base_timeout = 500ms, .retries = 0u, .max_drain = std::chrono::milliseconds(500)};
  auto link = open_serial_link(pty.slave_path(), options, port_figures());
  std::vector<lbp::Command> batch;
  for (std::uint16_t i = 0; i < 16; ++i)
    batch.push_back(lbp::write(static_cast<std::uint16_t>(0x200 + 2 * i), lbp::DataSize::Two, 0x1000u + i));
  for (std::uint16_t i = 0; i < 16; ++i)
    batch.push_back(lbp::read(static_cast<std::uint16_t>(0x200 + 2 * i), lbp::DataSize::Two));
  batch.push_back(lbp::local_read(lbp::local::kGetCookie));
  const auto replies = link->execute(batch);
  ASSERT_EQ(replies.size(), batch.size());
  for (std::size_t i = 0; i < 16; ++i) EXPECT_EQ(replies[i], Bytes{});
  for (std::size_t i = 0; i < 16; ++i) EXPECT_EQ(replies[16 + i], lbp::to_le(0x1000u + i, 2));
  EXPECT_EQ(replies.back(), Bytes{0x5A});
  EXPECT_EQ(card.bad_crcs(), 0u);
  EXPECT_EQ(card.commands(), batch.size());
  EXPECT_GT(link->statistics().bursts, 1u) << "97 command bytes do not fit the 64-byte window";
  EXPECT_EQ(link->describe(), pty.slave_path());
  EXPECT_FALSE(link->notes().empty());
}

TEST(SerialStream, LinkDropsStaleBytesAndReportsASilentCard) {
  Pty pty;
  const SlaveQueue queue(pty);
  const PipelinedLinkOptions options{
      .base_timeout = 500ms, .retries = 0u, .max_drain = std::chrono::milliseconds(500)};
  std::unique_ptr<Link> link = open_serial_link(pty.slave_path(), options, port_figures());
  {
    PtyCard card(pty);
    pty.send(Bytes{0x00, 0x99});  // a late reply from an earlier exchange
    ASSERT_TRUE(i20::test::eventually([&] { return queue.queued() == 2; }))  // waiting on the port
        << queue.queued() << " bytes arrived";
    EXPECT_EQ(link->execute_one(lbp::local_read(lbp::local::kGetCookie)), Bytes{0x5A});
  }
  const auto start = Clock::now();
  try {
    link->execute_one(lbp::local_read(lbp::local::kGetCookie));
    FAIL() << "no card, yet a reply";
  } catch (const TimeoutError& e) {
    EXPECT_TRUE(contains(e.what(), pty.slave_path())) << e.what();
    EXPECT_TRUE(contains(e.what(), "W6")) << e.what();
  }
  EXPECT_LT(Clock::now() - start, 2s);
}
