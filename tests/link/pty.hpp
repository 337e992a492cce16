// SPDX-License-Identifier: GPL-2.0-or-later
// A pseudo-terminal pair for serial tests: SerialStream opens the slave side like a
// /dev/ttyUSB device; the test plays the far end on the master side.
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>

#include "fake_lbp_memory.hpp"
#include "lbp/preparse.hpp"

namespace i20::link::fake {

class Pty {
 public:
  Pty() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0)
      throw std::runtime_error("cannot create a pseudo-terminal");
    char name[128];
    if (::ptsname_r(master_, name, sizeof name) != 0) throw std::runtime_error("ptsname failed");
    slave_path_ = name;
  }
  ~Pty() { ::close(master_); }
  Pty(const Pty&) = delete;
  Pty& operator=(const Pty&) = delete;

  int master() const { return master_; }
  const std::string& slave_path() const { return slave_path_; }

  void send(lbp::ByteView bytes) const {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const auto n = ::write(master_, bytes.data() + done, bytes.size() - done);
      if (n <= 0) throw std::runtime_error("pty write failed");
      done += static_cast<std::size_t>(n);
    }
  }

  // Up to `count` bytes, waiting at most `timeout` in total.
  lbp::Bytes receive(std::size_t count, std::chrono::milliseconds timeout) const {
    lbp::Bytes out;
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (out.size() < count) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
      if (left.count() <= 0 || !wait_readable(static_cast<int>(left.count()))) break;
      lbp::Byte buffer[256];
      const auto n = ::read(master_, buffer, std::min(sizeof buffer, count - out.size()));
      if (n <= 0) break;
      out.insert(out.end(), buffer, buffer + n);
    }
    return out;
  }

  bool wait_readable(int timeout_ms) const {
    pollfd p{master_, POLLIN, 0};
    return ::poll(&p, 1, timeout_ms) > 0 && (p.revents & POLLIN);
  }

 private:
  int master_ = -1;
  std::string slave_path_;
};

// The slave side's input queue, as the program reading the port will find it. Bytes the test
// sends on the master reach that queue later (the kernel moves them in a work item), so a test
// that needs them there waits for the count instead of sleeping. Open it before the program
// under test opens the port (its exclusive access keeps later openers out); it reads nothing
// and takes no lock.
class SlaveQueue {
 public:
  explicit SlaveQueue(const Pty& pty)
      : fd_(::open(pty.slave_path().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK)) {
    if (fd_ < 0) throw std::runtime_error("cannot open the pseudo-terminal's slave side");
  }
  ~SlaveQueue() { ::close(fd_); }
  SlaveQueue(const SlaveQueue&) = delete;
  SlaveQueue& operator=(const SlaveQueue&) = delete;

  // Bytes received and not yet read.
  std::size_t queued() const {
    int n = 0;
    return ::ioctl(fd_, FIONREAD, &n) == 0 && n > 0 ? static_cast<std::size_t>(n) : 0;
  }

 private:
  int fd_;
};

// A FakeCard answering real LBP framing on the master side, in its own thread.
class PtyCard {
 public:
  explicit PtyCard(const Pty& pty) : pty_(pty), thread_([this] { serve(); }) {}
  ~PtyCard() { stop(); }
  void stop() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
  }
  std::size_t commands() const { return commands_; }
  std::size_t bad_crcs() const { return bad_crcs_; }
  FakeCard& card() { return card_; }  // only while the link is idle

 private:
  void serve() {
    lbp::CommandSplitter splitter;
    while (!stop_) {
      if (!pty_.wait_readable(20)) continue;
      lbp::Byte buffer[256];
      const auto n = ::read(pty_.master(), buffer, sizeof buffer);
      if (n <= 0) continue;
      splitter.push(lbp::ByteView(buffer, static_cast<std::size_t>(n)));
      for (auto next = splitter.next({}); next.status == lbp::CommandSplitter::Status::Frame;
           next = splitter.next({})) {
        ++commands_;
        if (!next.frame.crc_ok) {
          ++bad_crcs_;  // the 8I20 drops a command with a bad CRC
          continue;
        }
        if (auto data = card_.answer(next.frame.command)) pty_.send(FakeCard::wire(*data));
      }
    }
  }

  const Pty& pty_;
  FakeCard card_;
  std::atomic<bool> stop_{false};
  std::atomic<std::size_t> commands_{0};
  std::atomic<std::size_t> bad_crcs_{0};
  std::thread thread_;  // last: starts after the members it uses
};

}  // namespace i20::link::fake
