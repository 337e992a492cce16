// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/hal_lint_load.hpp"

#include <spawn.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>

#include "error/error.hpp"
#include "files/atomic_file.hpp"
#include "version/build_info.hpp"

extern char** environ;

namespace i20::ops {
namespace {

namespace fs = std::filesystem;
namespace L = i20::linuxcnc;

// The rig script: installed beside the programs, or in the source tree for a build-tree i20.
fs::path halrun_virtual(const fs::path& exe) {
  std::vector<fs::path> tried;
  if (!exe.empty())
    tried.push_back(exe.parent_path().parent_path() / std::string(build::kLibexecInstallRelative));
  tried.push_back(std::string(build::kLibexecInstallDir));
  if (!exe.empty() && exe.parent_path() == fs::path(std::string(build::kBuildBinDir)))
    tried.push_back(std::string(build::kSourceLibexecDir));
  std::string looked;
  for (const auto& dir : tried) {
    const fs::path script = dir / "i20-halrun-virtual";
    if (access(script.c_str(), X_OK) == 0) return script;
    if (!looked.empty()) looked += ", ";
    looked += dir.string();
  }
  throw Error("--load: i20-halrun-virtual is not installed (looked in " + looked + ")");
}

// A folder the HAL user (not root) can read, removed with everything in it.
class ReadableTempDir {
 public:
  ReadableTempDir() {
    std::string pattern = (fs::temp_directory_path() / "i20-hal-load.XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr)
      throw Error("--load: cannot make a temporary folder: " + std::string(std::strerror(errno)));
    path_ = pattern;
    fs::permissions(path_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                               fs::perms::others_read | fs::perms::others_exec);
  }
  ~ReadableTempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ReadableTempDir(const ReadableTempDir&) = delete;
  ReadableTempDir& operator=(const ReadableTempDir&) = delete;

  // Writes `text` as NAME, readable by everyone; returns its path.
  std::string put(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    files::write_file(file, text, files::Existing::Refuse);
    fs::permissions(file, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                              fs::perms::others_read);
    return file.string();
  }

 private:
  fs::path path_;
};

struct Ran {
  int status = -1;  // the exit status, or -1 when it did not exit
  std::string output;
};

// Runs argv with standard output and error into one pipe, and waits.
Ran run_capturing(const std::vector<std::string>& args) {
  int pipe_fds[2];
  if (pipe(pipe_fds) != 0) throw Error("--load: pipe: " + std::string(std::strerror(errno)));
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addclose(&actions, pipe_fds[0]);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], STDERR_FILENO);
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(pipe_fds[1]);
  Ran ran;
  if (spawned != 0) {
    close(pipe_fds[0]);
    throw Error("--load: cannot run " + args[0] + ": " + std::strerror(spawned));
  }
  char buffer[4096];
  for (ssize_t n; (n = read(pipe_fds[0], buffer, sizeof buffer)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    ran.output.append(buffer, static_cast<std::size_t>(n));
  }
  close(pipe_fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ran.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return ran;
}

std::string last_lines(const std::vector<std::string>& lines, std::size_t n) {
  std::string out;
  for (std::size_t i = lines.size() > n ? lines.size() - n : 0; i < lines.size(); ++i) {
    if (!out.empty()) out += " | ";
    out += lines[i];
  }
  return out;
}

}  // namespace

HalLoadResult load_in_halrun(const std::vector<L::HalSource>& sources, const std::optional<std::string>& ini,
                             const fs::path& program) {
  if (geteuid() != 0)
    throw UsageError(
        "--load needs root: it makes network namespaces for the virtual card (hm2_eth needs a real "
        "network interface); run it with sudo (halrun itself runs as you)");
  const L::LoadPlan plan = L::plan_load(sources);
  if (plan.need.ini && !ini)
    throw UsageError(
        "--load: the files read INI values ([JOINT_0]P, ...): give the configuration's INI file "
        "with --ini");
  const fs::path& exe = program;
  const fs::path sim = exe.parent_path() / "i20sim";
  if (access(sim.c_str(), X_OK) != 0) throw Error("--load: i20sim is not installed beside " + exe.string());
  const fs::path script = halrun_virtual(exe);

  const ReadableTempDir dir;
  std::map<std::string, std::string> copies;
  std::string wrapper = plan.need.motion ? "loadrt homemod\nloadrt tpmod\n" : "";
  for (std::size_t i = 0; i < sources.size(); ++i) {
    std::string name = std::to_string(i);
    name += "-";
    name += fs::path(sources[i].file).filename().string();
    const std::string copy = dir.put(name, plan.loadable[i]);
    copies[copy] = sources[i].file;
    wrapper += "source " + copy + "\n";
  }
  std::vector<std::string> args{script.string(),
                                sim.string(),
                                plan.need.card,
                                plan.need.board_ip,
                                std::to_string(plan.need.channels),
                                dir.put("load.hal", wrapper)};
  if (ini) args.push_back(dir.put("config.ini", *ini));

  const Ran ran = run_capturing(args);
  const auto reading = L::read_halrun_output(ran.output, copies);
  if (ran.status == 77) throw UsageError("--load cannot run halrun here: " + last_lines(reading.other, 1));
  if (reading.realtime_failed)
    throw Error("--load: LinuxCNC's realtime (rtapi_app) did not start, so nothing was judged: " +
                last_lines(reading.realtime_why, reading.realtime_why.size()));
  if (ran.status != 0 && reading.findings.empty())
    throw Error("--load: halrun failed against the virtual card: " + last_lines(reading.other, 3));
  HalLoadResult result{reading.findings, plan.left_out, {}};
  result.ran = "a virtual ";
  result.ran += plan.need.card == "7i96s" ? "7I96S" : "7I92T";
  result.ran += " at " + plan.need.board_ip;
  return result;
}

}  // namespace i20::ops
