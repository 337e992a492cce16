// SPDX-License-Identifier: GPL-2.0-or-later
#include "spawn.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdexcept>

namespace i20::test {

Spawned::Spawned(const std::string& name, const std::vector<std::string>& args) {
  const Child child = start(name, args);
  pid_ = child.pid;
  out_fd_ = child.out_fd;
  err_fd_ = child.err_fd;
}

Spawned::~Spawned() {
  if (pid_ > 0) {
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
  if (out_fd_ >= 0) close(out_fd_);
  if (err_fd_ >= 0) close(err_fd_);
}

bool Spawned::pump(int timeout_ms) {
  pollfd fds[2] = {{out_fd_, POLLIN, 0}, {err_fd_, POLLIN, 0}};
  if (out_fd_ < 0 && err_fd_ < 0) return false;
  if (poll(fds, 2, timeout_ms) <= 0) return true;
  char buf[4096];
  int* fd[2] = {&out_fd_, &err_fd_};
  std::string* sink[2] = {&out_, &err_};
  for (int i = 0; i < 2; ++i) {
    if (*fd[i] < 0 || !(fds[i].revents & (POLLIN | POLLHUP))) continue;
    const auto n = ::read(*fd[i], buf, sizeof buf);
    if (n > 0) {
      sink[i]->append(buf, static_cast<std::size_t>(n));
    } else {
      close(*fd[i]);
      *fd[i] = -1;
    }
  }
  return out_fd_ >= 0 || err_fd_ >= 0;
}

std::size_t Spawned::wait_for(const std::string& needle, std::size_t from,
                              std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (true) {
    if (const auto at = out_.find(needle, from); at != std::string::npos) return at;
    if (std::chrono::steady_clock::now() >= deadline || !pump(50)) return out_.find(needle, from);
  }
}

Result Spawned::finish(int sig, std::chrono::milliseconds timeout) {
  Result r;
  if (pid_ <= 0) return r;
  kill(pid_, sig);
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline && pump(50)) {
  }
  if (std::chrono::steady_clock::now() >= deadline) kill(pid_, SIGKILL);
  int status = 0;
  waitpid(pid_, &status, 0);
  pid_ = -1;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = out_;
  r.err = err_;
  return r;
}

}  // namespace i20::test
