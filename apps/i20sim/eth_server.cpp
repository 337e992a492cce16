#include "eth_server.hpp"

#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <iostream>
#include <string>

#include "ethsim/server.hpp"
#include "sim/control.hpp"

namespace i20::sim::app {
namespace {

// The one process-wide flag a signal handler can reach; the server polls it every tick.
std::atomic<bool> g_stop{false};
extern "C" void on_stop_signal(int) {
  g_stop.store(true);
}

ethsim::ServerOptions server_options(const SimOptions& sim, const EthServeOptions& o) {
  ethsim::ServerOptions s;
  s.listen = ethsim::parse_listen_address(o.listen);
  s.card = ethsim::parse_card_kind(o.card);
  s.amplifier = sim.device;  // map, EEPROM file, world, injection: as for --pty
  s.amplifiers.clear();
  for (unsigned ch = 0; ch < o.channels; ++ch) s.amplifiers.push_back({0, ch});
  return s;
}

// Applies one control line to the 8I20 on port 0 channel 0 and prints its answer.
void control(ethsim::CardServer& server, const std::string& line) {
  if (line.empty()) return;
  try {
    const auto answer = server.with_card([&](ethsim::VirtualCard& card) {
      auto* amp = server.amplifier(card, 0, 0);
      return amp ? apply_control(*amp, line, Clock::now()) : std::string("no 8I20 on port 0 channel 0");
    });
    std::cout << answer << std::endl;
  } catch (const Error& e) {
    std::cout << "error: " << e.what() << std::endl;
  }
}

}  // namespace

int serve_eth(const SimOptions& sim, const EthServeOptions& o) {
  ethsim::CardServer server(server_options(sim, o));
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  std::cout << server.address().ip << ":" << server.address().port << std::endl;
  std::cerr << "i20sim: " << server.describe() << " with " << o.channels << " 8I20(s) on SSERIAL port 0"
            << std::endl;
  server.start();
  std::string pending;
  bool stdin_open = o.read_stdin;
  while (!g_stop.load()) {
    if (!stdin_open) {
      usleep(20000);
      continue;
    }
    pollfd p{STDIN_FILENO, POLLIN, 0};
    if (poll(&p, 1, 50) <= 0) continue;
    char buf[256];
    const auto n = ::read(STDIN_FILENO, buf, sizeof buf);
    if (n <= 0) {
      stdin_open = false;
      continue;
    }
    pending.append(buf, static_cast<std::size_t>(n));
    for (auto nl = pending.find('\n'); nl != std::string::npos; nl = pending.find('\n')) {
      control(server, pending.substr(0, nl));
      pending.erase(0, nl + 1);
    }
  }
  server.stop();
  return 0;
}

}  // namespace i20::sim::app
