// SPDX-License-Identifier: GPL-2.0-or-later
#include "browser_open.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <system_error>
#include <thread>
#include <vector>

extern char** environ;

namespace i20::cli {
namespace {

namespace fs = std::filesystem;

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return false;
  const std::string list = path;
  for (std::size_t begin = 0; begin <= list.size();) {
    const std::size_t end = std::min(list.find(':', begin), list.size());
    const fs::path candidate = fs::path(list.substr(begin, end - begin)) / program;
    if (end > begin && ::access(candidate.c_str(), X_OK) == 0) return true;
    begin = end + 1;
  }
  return false;
}

// An HTML page that sends the browser on to `url` (the URL holds only [0-9a-f.:/?=] here).
std::string redirect_page(const std::string& url) {
  std::string page =
      "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><meta http-equiv=\"refresh\" content=\"0;url=";
  page += url;
  page += "\"><title>i20 console</title></head><body><a href=\"";
  page += url;
  page += "\">i20 console</a></body></html>\n";
  return page;
}

}  // namespace

BrowserLauncher::~BrowserLauncher() {
  if (dir_.empty()) return;
  std::error_code ec;
  fs::remove_all(dir_, ec);
}

bool BrowserLauncher::desktop_present() {
  const bool display = std::getenv("DISPLAY") != nullptr || std::getenv("WAYLAND_DISPLAY") != nullptr;
  return display && ::isatty(STDOUT_FILENO) == 1 && on_path("xdg-open");
}

bool BrowserLauncher::open(const std::string& url) {
  std::string pattern = (fs::temp_directory_path() / "i20-console.XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) return false;  // mkdtemp makes it 0700
  dir_ = pattern;
  const fs::path page = dir_ / "open.html";
  {
    std::ofstream out(page);
    out << redirect_page(url);
    if (!out.flush()) return false;
  }
  fs::permissions(page, fs::perms::owner_read | fs::perms::owner_write);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // The browser's own chatter is not the console's output.
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  std::string program = "xdg-open";
  std::string file = page.string();
  std::vector<char*> argv{program.data(), file.data(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, "xdg-open", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return false;
  // xdg-open hands the file to the browser and exits: reap it without waiting here.
  std::thread([pid] { ::waitpid(pid, nullptr, 0); }).detach();
  return true;
}

}  // namespace i20::cli
