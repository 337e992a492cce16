// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth_server.hpp"

#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <iostream>
#include <optional>
#include <string>

#include "control_fifo.hpp"
#include "ethsim/card_control.hpp"
#include "ethsim/server.hpp"

namespace i20::sim::app {
namespace {

// The one process-wide flag a signal handler can reach; the loop below polls it.
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
  if (o.running_host) s.host = ethsim::HostOptions{};
  return s;
}

// Applies one control line and prints its answer (errors too: the server keeps serving).
void control(ethsim::CardServer& server, const std::string& line) {
  std::string answer;
  try {
    answer = ethsim::apply_card_control(server, line);
  } catch (const Error& e) {
    answer = std::string("error: ") + e.what();
  }
  if (!answer.empty()) std::cout << answer << (answer.back() == '\n' ? "" : "\n") << std::flush;
}

}  // namespace

int serve_eth(const SimOptions& sim, const EthServeOptions& o,
              const std::vector<std::string>& startup_control) {
  ethsim::CardServer server(server_options(sim, o));
  for (const auto& m : o.motors)
    server.with_card([&](ethsim::VirtualCard& card) {
      sim::Virtual8i20* amplifier = server.amplifier(card, 0, m.channel);
      if (!amplifier)
        throw UsageError("motor '" + m.name + "' sits on channel " + std::to_string(m.channel) +
                         ", which has no 8I20 (--channels " + std::to_string(o.channels) + ")");
      amplifier->amplifier().attach_motor(m, sim::Clock::now());
    });
  std::optional<ControlFifo> fifo;
  if (!o.control_fifo.empty()) fifo.emplace(o.control_fifo);
  for (const auto& line : startup_control) ethsim::apply_card_control(server, "all " + line);
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  std::cout << server.address().ip << ":" << server.address().port << std::endl;
  std::cerr << "i20sim: " << server.describe() << " with " << o.channels << " 8I20(s) on SSERIAL port 0"
            << (o.running_host ? ", another host running them" : "") << std::endl;
  server.start();
  LineSplitter from_stdin, from_fifo;
  bool stdin_open = o.read_stdin;
  while (!g_stop.load()) {
    std::vector<pollfd> fds;
    if (stdin_open) fds.push_back({STDIN_FILENO, POLLIN, 0});
    if (fifo) fds.push_back({fifo->fd(), POLLIN, 0});
    if (fds.empty()) {
      usleep(20000);
      continue;
    }
    if (poll(fds.data(), fds.size(), 50) <= 0) continue;
    for (const pollfd& p : fds) {
      if (!(p.revents & (POLLIN | POLLHUP))) continue;
      bool eof = false;
      auto& splitter = p.fd == STDIN_FILENO ? from_stdin : from_fifo;
      for (const auto& line : splitter.read_from(p.fd, eof)) control(server, line);
      if (eof && p.fd == STDIN_FILENO) stdin_open = false;
    }
  }
  server.stop();
  return 0;
}

}  // namespace i20::sim::app
