// SPDX-License-Identifier: GPL-2.0-or-later
// Figures for `i20 console` on loopback, against the in-process simulator (--sim): a real
// card's serial exchanges add their own time to every figure that reads it.
//   - startup: from the program's start until it prints its URL (the card opened and identified);
//   - page usable: the requests the page makes before it shows the overview (the token
//     redirect, index.html, app.js, style.css, /api/overview), each on a fresh connection;
//   - /api/params: every parameter read and rendered;
//   - live: samples per second over a WebSocket, and the latency from the sample's timestamp
//     (taken before the card is read) to its arrival;
//   - the server's resident memory after startup and after the runs above.
// Run: build/bin/i20-bench-console [seconds of live samples, default 5]
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <regex>
#include <stdexcept>
#include <string>
#include <vector>

#include "build_paths.hpp"
#include "raw_client.hpp"

extern char** environ;

namespace {

using Clock = std::chrono::steady_clock;
using i20::console::testing::ask;
using i20::console::testing::cat;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// `i20 --sim console --listen-port 0`, stopped with Ctrl-C (SIGINT) at the end.
class Console {
 public:
  Console() {
    int out[2];
    if (::pipe(out) != 0) throw std::runtime_error("pipe");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
    posix_spawn_file_actions_addclose(&actions, out[0]);
    std::string exe = (i20::test::bin_dir() / "i20").string();
    std::vector<std::string> args{exe, "--sim", "console", "--listen-port", "0"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const auto start = Clock::now();
    const int rc = posix_spawn(&pid_, exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(out[1]);
    if (rc != 0) throw std::runtime_error("cannot start " + exe);
    std::string text;
    const std::regex url(R"(http://127\.0\.0\.1:(\d+)/\?token=([0-9a-f]{32}))");
    std::smatch m;
    char buffer[256];
    while (!std::regex_search(text, m, url)) {
      const auto n = ::read(out[0], buffer, sizeof buffer);
      if (n <= 0) throw std::runtime_error("i20 console printed no URL");
      text.append(buffer, static_cast<std::size_t>(n));
    }
    startup_ms_ = ms_since(start);
    port_ = static_cast<unsigned short>(std::stoi(m[1]));
    token_ = m[2];
    out_fd_ = out[0];
  }
  ~Console() {
    ::kill(pid_, SIGINT);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    ::close(out_fd_);
  }
  Console(const Console&) = delete;
  Console& operator=(const Console&) = delete;

  double startup_ms() const { return startup_ms_; }
  unsigned short port() const { return port_; }
  std::string cookie() const { return cat("Cookie: i20_console=", token_, "\r\n"); }
  const std::string& token() const { return token_; }
  std::string origin() const { return cat("Origin: http://127.0.0.1:", std::to_string(port_), "\r\n"); }
  // VmRSS of the server, kB.
  long rss_kb() const {
    std::ifstream status(cat("/proc/", std::to_string(pid_), "/status"));
    std::string line;
    while (std::getline(status, line))
      if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
    return -1;
  }

 private:
  pid_t pid_ = -1;
  int out_fd_ = -1;
  double startup_ms_ = 0;
  unsigned short port_ = 0;
  std::string token_;
};

struct Stats {
  double median = 0, p95 = 0, max = 0;
};
Stats stats(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  return {v[v.size() / 2], v[std::min(v.size() - 1, v.size() * 95 / 100)], v.back()};
}

void expect(const i20::console::testing::Reply& r, int status, const char* what) {
  if (r.status != status) throw std::runtime_error(cat(what, ": HTTP ", std::to_string(r.status)));
}

double page_load_ms(const Console& c) {
  const auto start = Clock::now();
  const auto p = c.port();
  expect(ask(p, i20::console::testing::get_request(p, cat("/?token=", c.token()))), 303, "token redirect");
  for (const char* file : {"/", "/app.js", "/style.css", "/api/overview"})
    expect(ask(p, i20::console::testing::get_request(p, file, c.cookie())), 200, file);
  return ms_since(start);
}

// Reads WebSocket frames (the server's are unmasked, text, under 64 KiB) for `seconds`:
// the arrival time of each and its "t" (ms since the epoch when the sample was taken).
std::vector<std::pair<double, double>> live_samples(const Console& c, double seconds) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(c.port());
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0)
    throw std::runtime_error("connect");
  const auto request = cat("GET /api/live HTTP/1.1\r\nHost: 127.0.0.1:", std::to_string(c.port()), "\r\n",
                           c.cookie(), c.origin(),
                           "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
                           "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n");
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size()))
    throw std::runtime_error("send");
  std::string data;
  std::vector<std::pair<double, double>> out;
  bool upgraded = false;
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  const std::regex stamp(R"("t":(\d+))");
  while (Clock::now() < end) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 200) <= 0) continue;
    char buffer[4096];
    const auto n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    data.append(buffer, static_cast<std::size_t>(n));
    if (!upgraded) {
      const auto head_end = data.find("\r\n\r\n");
      if (head_end == std::string::npos) continue;
      if (data.rfind("HTTP/1.1 101", 0) != 0) throw std::runtime_error("WebSocket refused");
      data.erase(0, head_end + 4);
      upgraded = true;
    }
    for (;;) {
      if (data.size() < 2) break;
      std::size_t len = static_cast<unsigned char>(data[1]) & 0x7F, header = 2;
      if (len == 126) {
        if (data.size() < 4) break;
        len = (static_cast<unsigned char>(data[2]) << 8) | static_cast<unsigned char>(data[3]);
        header = 4;
      }
      if (data.size() < header + len) break;
      const std::string payload = data.substr(header, len);
      data.erase(0, header + len);
      std::smatch m;
      if (!std::regex_search(payload, m, stamp)) continue;
      const double now_ms =
          std::chrono::duration<double, std::milli>(std::chrono::system_clock::now().time_since_epoch())
              .count();
      out.emplace_back(now_ms, std::stod(m[1]));
    }
  }
  ::close(fd);
  return out;
}

int run(double live_seconds) {
  std::vector<double> startups;
  for (int i = 0; i < 5; ++i) startups.push_back(Console().startup_ms());
  const auto s = stats(startups);
  std::printf("i20 console on loopback, simulated card (--sim)\n");
  std::printf("  startup until the URL is printed   median %.1f ms, max %.1f ms (5 runs)\n", s.median, s.max);

  Console c;
  const long rss_start = c.rss_kb();
  std::vector<double> loads;
  for (int i = 0; i < 50; ++i) loads.push_back(page_load_ms(c));
  const auto l = stats(loads);
  std::printf("  page usable (redirect, 3 files, /api/overview)  median %.1f ms, p95 %.1f ms (50 loads)\n",
              l.median, l.p95);
  std::vector<double> params;
  for (int i = 0; i < 50; ++i) {
    const auto start = Clock::now();
    expect(ask(c.port(), i20::console::testing::get_request(c.port(), "/api/params", c.cookie())), 200,
           "params");
    params.push_back(ms_since(start));
  }
  const auto pr = stats(params);
  std::printf("  /api/params (every value read)     median %.1f ms, p95 %.1f ms (50 requests)\n", pr.median,
              pr.p95);

  const auto samples = live_samples(c, live_seconds);
  if (samples.size() < 2) throw std::runtime_error("no live samples");
  const double span_s = (samples.back().first - samples.front().first) / 1000.0;
  std::vector<double> latency;
  for (const auto& [arrived, taken] : samples) latency.push_back(arrived - taken);
  const auto lat = stats(latency);
  std::printf(
      "  live: %zu samples in %.1f s = %.1f samples/s; latency median %.1f ms, p95 %.1f ms, max %.1f ms\n",
      samples.size(), span_s, static_cast<double>(samples.size() - 1) / span_s, lat.median, lat.p95, lat.max);
  std::printf("  server memory (VmRSS)              %ld kB after startup, %ld kB after the runs above\n",
              rss_start, c.rss_kb());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc > 1 ? std::stod(argv[1]) : 5.0);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "i20-bench-console: %s\n", e.what());
    return 1;
  }
}
