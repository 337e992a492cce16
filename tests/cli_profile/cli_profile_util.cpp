// SPDX-License-Identifier: GPL-2.0-or-later
#include "cli_profile_util.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

namespace i20::test {

std::string shipped(const std::string& name) {
  return (source_dir() / "profiles" / name).string();
}

std::string write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
  return path.string();
}

std::string slurp_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

Result i20_on(const std::string& port, std::vector<std::string> args, int timeout_s) {
  args.insert(args.begin(), {"--port", port, "--no-user-params"});
  return run("i20", args, {}, timeout_s);
}

Background::Background(const std::vector<std::string>& args) {
  const auto exe = program("i20").string();
  std::vector<std::string> keep{exe};
  keep.insert(keep.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : keep) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto out = (dir_ / "out").string(), err = (dir_ / "err").string();
  pid_ = fork();
  if (pid_ == 0) {
    dup2(open("/dev/null", O_RDONLY), STDIN_FILENO);
    dup2(open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), STDOUT_FILENO);
    dup2(open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), STDERR_FILENO);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
}

Background::~Background() {
  if (pid_ <= 0) return;
  kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
}

void Background::interrupt() {
  kill(pid_, SIGINT);
}

Result Background::wait(int timeout_s) {
  Result r;
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_s);
  while (waitpid(pid_, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  pid_ = -1;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp_file(dir_ / "out");
  r.err = slurp_file(dir_ / "err");
  return r;
}

namespace {

// The command bytes of a trace line "i20sim: 65 28 00 00 7d -> ", or nothing.
std::vector<unsigned> command_bytes(const std::string& line) {
  const auto start = line.find("i20sim: ");
  const auto arrow = line.find(" -> ");
  if (start == std::string::npos || arrow == std::string::npos) return {};
  std::istringstream in(line.substr(start + 8, arrow - start - 8));
  std::vector<unsigned> bytes;
  for (std::string b; in >> b;) bytes.push_back(static_cast<unsigned>(std::stoul(b, nullptr, 16)));
  return bytes;
}

// A data write: not a local command (bit 7), write bit (5) set.
bool is_data_write(const std::vector<unsigned>& bytes) {
  return !bytes.empty() && !(bytes[0] & 0x80) && (bytes[0] & 0x20);
}

bool leaves_nv_mode(const std::string& line, const std::vector<unsigned>& bytes) {
  if (line.find("injected reset") != std::string::npos || line.find("power on") != std::string::npos)
    return true;
  return bytes.size() >= 2 && bytes[0] == 0xFE && bytes[1] == 0x5A;  // software reset
}

}  // namespace

std::size_t eeprom_writes(const std::string& trace) {
  std::istringstream in(trace);
  bool nv = false;
  std::size_t count = 0;
  for (std::string line; std::getline(in, line);) {
    const auto bytes = command_bytes(line);
    if (leaves_nv_mode(line, bytes)) {
      nv = false;
    } else if (bytes.size() >= 2 && bytes[0] == 0xEC) {
      nv = bytes[1] == 0x01;
    } else if (nv && is_data_write(bytes)) {
      ++count;
    }
  }
  return count;
}

std::size_t data_writes(const std::string& trace) {
  std::istringstream in(trace);
  std::size_t count = 0;
  for (std::string line; std::getline(in, line);) count += is_data_write(command_bytes(line)) ? 1 : 0;
  return count;
}

std::vector<std::filesystem::path> backups_in(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().filename().string().rfind("i20-backup-", 0) == 0) out.push_back(entry.path());
  return out;
}

YAML::Node json(const Result& r) {
  try {
    return YAML::Load(r.out);
  } catch (const YAML::Exception& e) {
    ADD_FAILURE() << "not JSON: " << e.what() << "\nstdout:\n" << r.out << "\nstderr:\n" << r.err;
    return {};
  }
}

std::int64_t sim_value(SimProcess& sim, const std::string& name) {
  const std::string answer = sim.control("get " + name);
  try {
    return std::stoll(answer);
  } catch (const std::exception&) {
    ADD_FAILURE() << "i20sim answered '" << answer << "' to get " << name;
    return -1;
  }
}

std::string outcome(const YAML::Node& report) {
  return report["outcome"] ? report["outcome"].as<std::string>() : "(no outcome)";
}

namespace {

void expect_holds(const ValueOf& value_of, const std::string& cell, std::int64_t want,
                  const std::string& what, const std::string& label) {
  EXPECT_EQ(value_of(cell), want) << label << ": the report says " << cell << " holds its " << what
                                  << " value, the card holds something else";
}

void expect_rollback_failed_matches(const YAML::Node& report, const ValueOf& value_of,
                                    const std::string& label) {
  std::set<std::string> reported;
  for (const auto& c : report["cells"]) {
    const auto cell = c["cell"].as<std::string>();
    const auto status = c["status"].as<std::string>();
    reported.insert(cell);
    if (status == "intended") expect_holds(value_of, cell, c["intended"].as<std::int64_t>(), "new", label);
    if (status == "original") expect_holds(value_of, cell, c["original"].as<std::int64_t>(), "old", label);
    if (status == "other") expect_holds(value_of, cell, c["actual"].as<std::int64_t>(), "read-back", label);
  }
  for (const auto& s : report["plan"]["steps"]) {
    const auto cell = s["cell"].as<std::string>();
    if (!reported.contains(cell))
      expect_holds(value_of, cell, s["card_raw"].as<std::int64_t>(), "old", label);
  }
}

}  // namespace

void expect_report_matches_card(const YAML::Node& report, const ValueOf& value_of, const std::string& label) {
  const std::string what = outcome(report);
  if (what == "failed") return;  // no plan: the caller compares with the values before
  const auto plan = report["plan"];
  if (what == "done" || what == "nothing-to-do") {
    for (const auto& s : plan["steps"])
      expect_holds(value_of, s["cell"].as<std::string>(), s["profile_raw"].as<std::int64_t>(), "new", label);
    for (const auto& s : plan["unchanged"])
      expect_holds(value_of, s["cell"].as<std::string>(), s["profile_raw"].as<std::int64_t>(), "new", label);
    return;
  }
  if (what == "uncertain") return expect_rollback_failed_matches(report, value_of, label);
  // Rolled back, refused, dry run: every planned cell holds what it held before.
  for (const auto& s : plan["steps"])
    expect_holds(value_of, s["cell"].as<std::string>(), s["card_raw"].as<std::int64_t>(), "old", label);
  for (const auto& c : report["cells"])
    EXPECT_EQ(c["status"].as<std::string>(), "original") << label << ": " << c["cell"].as<std::string>();
}

}  // namespace i20::test
