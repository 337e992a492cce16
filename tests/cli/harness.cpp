// SPDX-License-Identifier: GPL-2.0-or-later
#include "harness.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace i20::test {
namespace {

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<char*> c_args(const std::string& exe, const std::vector<std::string>& args,
                          std::vector<std::string>& keep) {
  keep.clear();
  keep.push_back(exe);
  keep.insert(keep.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : keep) argv.push_back(a.data());
  argv.push_back(nullptr);
  return argv;
}

void apply_env(const std::map<std::string, std::string>& env) {
  for (const auto& [k, v] : env) {
    if (v.empty())
      unsetenv(k.c_str());
    else
      setenv(k.c_str(), v.c_str(), 1);
  }
}

// Reads both pipes until the child closes them or the deadline passes.
void drain(int out_fd, int err_fd, std::string& out, std::string& err,
           std::chrono::steady_clock::time_point deadline) {
  pollfd fds[2] = {{out_fd, POLLIN, 0}, {err_fd, POLLIN, 0}};
  int open_fds = 2;
  char buf[4096];
  while (open_fds > 0 && std::chrono::steady_clock::now() < deadline) {
    if (poll(fds, 2, 100) <= 0) continue;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP))) continue;
      const auto n = ::read(fds[i].fd, buf, sizeof buf);
      if (n <= 0) {
        ::close(fds[i].fd);
        fds[i].fd = -1;
        --open_fds;
      } else {
        (i == 0 ? out : err).append(buf, static_cast<std::size_t>(n));
      }
    }
  }
  for (auto& f : fds)
    if (f.fd >= 0) ::close(f.fd);
}

}  // namespace

std::filesystem::path program(const std::string& name) {
  return bin_dir() / name;
}

Child start(const std::string& name, const std::vector<std::string>& args,
            const std::map<std::string, std::string>& env) {
  const auto exe = program(name).string();
  int out_pipe[2], err_pipe[2];
  if (pipe(out_pipe) != 0 || pipe(err_pipe) != 0) throw std::runtime_error("pipe failed");
  std::vector<std::string> keep;
  auto argv = c_args(exe, args, keep);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out_pipe[1], STDOUT_FILENO);
    dup2(err_pipe[1], STDERR_FILENO);
    const int devnull = open("/dev/null", O_RDONLY);
    dup2(devnull, STDIN_FILENO);
    close(out_pipe[0]);
    close(err_pipe[0]);
    apply_env(env);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  close(out_pipe[1]);
  close(err_pipe[1]);
  return {pid, out_pipe[0], err_pipe[0]};
}

Result run(const std::string& name, const std::vector<std::string>& args,
           const std::map<std::string, std::string>& env, int timeout_s) {
  const Child child = start(name, args, env);
  Result r;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_s);
  drain(child.out_fd, child.err_fd, r.out, r.err, deadline);
  int status = 0;
  if (std::chrono::steady_clock::now() >= deadline) kill(child.pid, SIGKILL);
  waitpid(child.pid, &status, 0);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return r;
}

TempDir::TempDir() {
  std::random_device rd;
  path_ =
      std::filesystem::temp_directory_path() / ("i20test-" + std::to_string(rd()) + std::to_string(getpid()));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

SimProcess::SimProcess(const std::vector<std::string>& args, Transport transport) {
  std::random_device rd;
  trace_file_ = std::filesystem::temp_directory_path() / ("i20sim-trace-" + std::to_string(rd()) + ".log");
  int in_pipe[2], out_pipe[2];
  if (pipe(in_pipe) != 0 || pipe(out_pipe) != 0) throw std::runtime_error("pipe failed");
  std::vector<std::string> all = transport == Transport::Pty
                                     ? std::vector<std::string>{"--pty", "--trace"}
                                     : std::vector<std::string>{"--eth", "127.0.0.1:0"};
  all.insert(all.end(), args.begin(), args.end());
  const auto exe = program("i20sim").string();
  std::vector<std::string> keep;
  auto argv = c_args(exe, all, keep);
  pid_ = fork();
  if (pid_ == 0) {
    dup2(in_pipe[0], STDIN_FILENO);
    dup2(out_pipe[1], STDOUT_FILENO);
    const int trace = open(trace_file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(trace, STDERR_FILENO);
    close(in_pipe[1]);
    close(out_pipe[0]);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  close(in_pipe[0]);
  close(out_pipe[1]);
  stdin_fd_ = in_pipe[1];
  stdout_fd_ = out_pipe[0];
  port_ = read_line(10000);
  const bool looks_right =
      transport == Transport::Pty ? port_.rfind("/dev/", 0) == 0 : port_.rfind("127.", 0) == 0;
  if (!looks_right)
    throw std::runtime_error("i20sim did not print a port path; stderr: " + slurp(trace_file_));
}

SimProcess::~SimProcess() {
  if (pid_ > 0) {
    kill(pid_, SIGTERM);
    int status = 0;
    for (int i = 0; i < 50 && waitpid(pid_, &status, WNOHANG) == 0; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    kill(pid_, SIGKILL);
    waitpid(pid_, &status, WNOHANG);
  }
  if (stdin_fd_ >= 0) close(stdin_fd_);
  if (stdout_fd_ >= 0) close(stdout_fd_);
  std::error_code ec;
  std::filesystem::remove(trace_file_, ec);
}

std::string SimProcess::read_line(int timeout_ms) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (true) {
    const auto nl = pending_.find('\n');
    if (nl != std::string::npos) {
      std::string line = pending_.substr(0, nl);
      pending_.erase(0, nl + 1);
      return line;
    }
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0)
      throw std::runtime_error("i20sim did not answer within " + std::to_string(timeout_ms) + " ms");
    pollfd p{stdout_fd_, POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    char buf[512];
    const auto n = ::read(stdout_fd_, buf, sizeof buf);
    if (n <= 0) throw std::runtime_error("i20sim closed its stdout");
    pending_.append(buf, static_cast<std::size_t>(n));
  }
}

std::string SimProcess::control(const std::string& line) {
  const std::string text = line + "\n";
  if (::write(stdin_fd_, text.data(), text.size()) != static_cast<ssize_t>(text.size()))
    throw std::runtime_error("cannot write to i20sim's stdin");
  return read_line(5000);
}

std::string SimProcess::trace() const {
  return slurp(trace_file_);
}

std::size_t SimProcess::commands_seen() const {
  std::istringstream in(trace());
  std::size_t count = 0;
  for (std::string line; std::getline(in, line);)
    if (line.find(" -> ") != std::string::npos) ++count;
  return count;
}

std::size_t SimProcess::writes_seen() const {
  std::istringstream in(trace());
  std::size_t count = 0;
  for (std::string line; std::getline(in, line);) {
    const auto pos = line.find(": ");
    if (pos == std::string::npos || line.find(" -> ") == std::string::npos) continue;
    if ((std::stoi(line.substr(pos + 2, 2), nullptr, 16) & 0xE0) == 0x60) ++count;
  }
  return count;
}

}  // namespace i20::test
