// SPDX-License-Identifier: GPL-2.0-or-later
#include "server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>

#include <array>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <iostream>
#include <vector>

#include "control_fifo.hpp"
#include "params/text.hpp"
#include "pty.hpp"
#include "sim/control.hpp"
#include "sim/error.hpp"

namespace i20::sim::app {
namespace {

// Self-pipe: the signal handler only writes a byte; the poll loop sees it and exits.
volatile std::sig_atomic_t g_signal_fd = -1;

extern "C" void on_signal(int) {
  const int saved = errno;
  const char byte = 1;
  if (g_signal_fd >= 0) {
    const ssize_t ignored = ::write(g_signal_fd, &byte, 1);  // nothing to do if the pipe is full
    (void)ignored;
  }
  errno = saved;
}

class SignalPipe {
 public:
  SignalPipe() {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC | O_NONBLOCK) != 0)
      throw ConfigError("pipe2 failed: " + std::string(std::strerror(errno)));
    read_.reset(fds[0]);
    write_.reset(fds[1]);
    g_signal_fd = write_.get();
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    ::sigaction(SIGINT, &sa, nullptr);
    ::sigaction(SIGTERM, &sa, nullptr);
    ::signal(SIGPIPE, SIG_IGN);
  }
  ~SignalPipe() {
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    g_signal_fd = -1;
  }
  SignalPipe(const SignalPipe&) = delete;
  SignalPipe& operator=(const SignalPipe&) = delete;
  int fd() const { return read_.get(); }

 private:
  UniqueFd read_, write_;
};

// Collects bytes into lines and applies each one to the card.
class ControlReader {
 public:
  // Returns false at end of input.
  bool read_from(int fd, Virtual8i20& card) {
    std::array<char, 512> buf;
    const ssize_t n = ::read(fd, buf.data(), buf.size());
    if (n == 0) return false;
    if (n < 0) return errno == EAGAIN || errno == EINTR;
    for (ssize_t i = 0; i < n; ++i) {
      if (buf[i] != '\n') {
        pending_ += buf[i];
        continue;
      }
      answer(card, pending_);
      pending_.clear();
    }
    return true;
  }

 private:
  static void answer(Virtual8i20& card, const std::string& line) {
    std::string reply;
    try {
      reply = apply_control(card, line, Clock::now());
    } catch (const ControlError& e) {
      reply = std::string("error: ") + params::printable(e.what());
    }
    if (!reply.empty()) std::cout << reply << (reply.back() == '\n' ? "" : "\n") << std::flush;
  }

  std::string pending_;
};

timespec until(std::optional<Clock::time_point> wake) {
  const auto left = wake ? std::max(*wake - Clock::now(), Clock::duration::zero()) : std::chrono::seconds(1);
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
  return timespec{static_cast<time_t>(ns / 1000000000), static_cast<long>(ns % 1000000000)};
}

class Server {
 public:
  Server(Virtual8i20& card, WireOptions wire, const ServerOptions& options)
      : card_(card), model_(card, wire), read_stdin_(options.read_stdin) {
    if (!options.control_fifo.empty()) fifo_.emplace(options.control_fifo);
  }

  int run() {
    std::cout << pty_.slave_path() << '\n' << std::flush;
    for (;;) {
      std::vector<pollfd> fds{{signals_.fd(), POLLIN, 0}, {pty_.master(), POLLIN, 0}};
      if (!to_client_.empty()) fds[1].events |= POLLOUT;
      if (read_stdin_) fds.push_back({STDIN_FILENO, POLLIN, 0});
      if (fifo_) fds.push_back({fifo_->fd(), POLLIN, 0});
      const timespec timeout = until(model_.next_wake());
      if (::ppoll(fds.data(), fds.size(), &timeout, nullptr) < 0 && errno != EINTR)
        throw ConfigError(std::string("poll failed: ") + std::strerror(errno));
      if (fds[0].revents) return 0;
      if (fds[1].revents & POLLIN) from_client();
      for (std::size_t i = 2; i < fds.size(); ++i) {
        if (!(fds[i].revents & (POLLIN | POLLHUP))) continue;
        if (fds[i].fd == STDIN_FILENO && !control_.read_from(STDIN_FILENO, card_)) read_stdin_ = false;
        if (fifo_ && fds[i].fd == fifo_->fd()) control_.read_from(fifo_->fd(), card_);
      }
      to_client();
    }
  }

 private:
  void from_client() {
    std::array<lbp::Byte, 4096> buf;
    const ssize_t n = ::read(pty_.master(), buf.data(), buf.size());
    if (n > 0) model_.host_write(lbp::ByteView(buf.data(), static_cast<std::size_t>(n)), Clock::now());
  }

  void to_client() {
    const auto now = Clock::now();
    model_.pump(now);
    std::array<lbp::Byte, 4096> buf;
    for (std::size_t n; (n = model_.host_read(buf, now)) > 0;)
      to_client_.insert(to_client_.end(), buf.begin(), buf.begin() + n);
    if (to_client_.empty()) return;
    // The master is non-blocking: what the pty cannot take now waits for POLLOUT.
    const ssize_t n = ::write(pty_.master(), to_client_.data(), to_client_.size());
    if (n > 0) to_client_.erase(to_client_.begin(), to_client_.begin() + n);
  }

  Virtual8i20& card_;
  WireModel model_;
  bool read_stdin_;
  Pty pty_;
  SignalPipe signals_;
  std::optional<ControlFifo> fifo_;
  ControlReader control_;
  lbp::Bytes to_client_;
};

}  // namespace

int serve(Virtual8i20& card, WireOptions wire, const ServerOptions& options) {
  Server server(card, wire, options);
  return server.run();
}

}  // namespace i20::sim::app
