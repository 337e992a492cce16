// SPDX-License-Identifier: GPL-2.0-or-later
// Runs the toolkit's programs as processes, the way users do, against `i20sim --pty`.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "build_paths.hpp"

namespace i20::test {

struct Result {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// build/bin joined with the program name (source_dir() and bin_dir(): build_paths.hpp).
std::filesystem::path program(const std::string& name);

// A started program: its pid and the read ends of its stdout and stderr (its stdin is
// /dev/null). The caller reads, waits for and closes them.
struct Child {
  int pid = -1;
  int out_fd = -1;
  int err_fd = -1;
};
Child start(const std::string& name, const std::vector<std::string>& args,
            const std::map<std::string, std::string>& env = {});

// Runs a program to completion with a deadline (killed after `timeout_s`), with extra
// environment variables (an empty value unsets the variable).
Result run(const std::string& name, const std::vector<std::string>& args,
           const std::map<std::string, std::string>& env = {}, int timeout_s = 60);

// A temporary directory removed at the end of the test.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// `i20sim --pty --trace ARGS...`: the port path, control lines on its stdin, the trace
// (every command the card received) collected from its stderr. With Transport::Eth it is
// `i20sim --eth 127.0.0.1:0 ARGS...` and port() is the card's "127.0.0.1:PORT".
class SimProcess {
 public:
  enum class Transport { Pty, Eth };
  explicit SimProcess(const std::vector<std::string>& args = {}, Transport transport = Transport::Pty);
  ~SimProcess();
  SimProcess(const SimProcess&) = delete;
  SimProcess& operator=(const SimProcess&) = delete;

  const std::string& port() const { return port_; }
  // Sends a control line ("busv 24", "get FAULT") and returns its one-line answer.
  std::string control(const std::string& line);
  // Everything the simulator traced so far.
  std::string trace() const;
  // Number of commands the card has executed so far (from the trace).
  std::size_t commands_seen() const;
  // Of those, data writes (LBP header 011x xxxx): 0 proves nothing was written.
  std::size_t writes_seen() const;

 private:
  int pid_ = -1;
  int stdin_fd_ = -1;
  int stdout_fd_ = -1;
  std::filesystem::path trace_file_;
  std::string port_;
  std::string pending_;
  std::string read_line(int timeout_ms);
};

}  // namespace i20::test
