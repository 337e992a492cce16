// SPDX-License-Identifier: GPL-2.0-or-later
// The benchmarks' simulator: `i20sim ARGS...` in the background, its first stdout line
// (the pty path, or the Ethernet card's ADDR:PORT) kept, stopped on every exit path:
// - normal return and exceptions: the destructor (run_main() below makes sure an escaping
//   exception unwinds the stack instead of calling std::terminate, which skips destructors);
// - a signal or a crash of the benchmark (SIGINT, SIGSEGV, even SIGKILL): the kernel sends
//   the simulator SIGTERM when the benchmark dies (Linux PR_SET_PDEATHSIG), so no signal
//   handler has to run destructors, which it could not do safely anyway.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>
#include <vector>

#include "build_paths.hpp"

namespace i20::bench {

class SimProcess {
 public:
  explicit SimProcess(const std::vector<std::string>& args) {
    const std::string exe = (i20::test::bin_dir() / "i20sim").string();
    std::vector<std::string> all{exe};
    all.insert(all.end(), args.begin(), args.end());
    all.emplace_back("--no-stdin");
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);

    int out[2];
    if (pipe(out) != 0) throw std::runtime_error("pipe");
    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ < 0) {
      close(out[0]);
      close(out[1]);
      throw std::runtime_error("cannot fork for " + exe);
    }
    if (pid_ == 0) exec_child(out, parent, exe.c_str(), argv.data());  // never returns
    close(out[1]);
    char c;
    while (read(out[0], &c, 1) == 1 && c != '\n') first_line_.push_back(c);
    close(out[0]);
    if (first_line_.empty()) {
      stop();
      throw std::runtime_error("i20sim printed nothing");
    }
  }
  ~SimProcess() { stop(); }
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  // The pty path (--pty) or "ADDR:PORT" (--eth).
  const std::string& address() const { return first_line_; }

 private:
  // In the child, between fork and exec: async-signal-safe calls only.
  [[noreturn]] static void exec_child(const int out[2], pid_t parent, const char* exe, char* const argv[]) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);  // the benchmark died before prctl: nobody to serve
    dup2(out[1], STDOUT_FILENO);
    close(out[0]);
    close(out[1]);
    const int null_in = open("/dev/null", O_RDONLY);
    const int null_out = open("/dev/null", O_WRONLY);
    if (null_in >= 0) dup2(null_in, STDIN_FILENO);
    if (null_out >= 0) dup2(null_out, STDERR_FILENO);
    execv(exe, argv);
    _exit(127);
  }

  void stop() noexcept {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

  pid_t pid_ = -1;
  std::string first_line_;
};

// Runs a program (a path and its arguments) with stdout and stderr to /dev/null and waits
// for it; returns its exit code, or -1 when a signal ended it.
inline int run_quiet(const std::vector<std::string>& args) {
  std::vector<std::string> all(args);
  std::vector<char*> argv;
  for (auto& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot fork for " + args.at(0));
  if (pid == 0) {
    const int null_out = open("/dev/null", O_WRONLY);
    if (null_out >= 0) {
      dup2(null_out, STDOUT_FILENO);
      dup2(null_out, STDERR_FILENO);
    }
    execv(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Runs a benchmark's body so that an exception unwinds (stopping its simulators) and
// ends the process with a message and exit code 1 instead of std::terminate.
template <class Body>
int run_main(Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "benchmark failed: %s\n", e.what());
  } catch (...) {
    std::fprintf(stderr, "benchmark failed: an unknown exception\n");
  }
  return 1;
}

}  // namespace i20::bench
