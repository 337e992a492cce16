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
#include "ethsim/board_control.hpp"
#include "ethsim/server.hpp"
#include "params/text.hpp"

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
  // "7i92t-servo": the 7I92T laid out with one encoder, three Hall inputs and an 8I20 per
  // axis (docs/virtual-feedback.md), for LinuxCNC's hm2_eth + bldc against --motor.
  if (o.card == "7i92t-servo") {
    s.card = ethsim::BoardKind::I7i92t;
    s.config = ethsim::BoardConfig::preset_7i92t_servo();
  } else {
    s.card = ethsim::parse_board_kind(o.card);
  }
  s.amplifier = sim.device;  // map, EEPROM file, world, injection: as for --pty
  s.amplifiers.clear();
  for (unsigned ch = 0; ch < o.channels; ++ch) s.amplifiers.push_back({0, ch});
  if (o.running_host) s.host = ethsim::HostOptions{};
  s.motors = o.motors;
  return s;
}

// Applies one control line and prints its answer (errors too: the server keeps serving).
void control(ethsim::BoardServer& server, const std::string& line) {
  std::string answer;
  try {
    answer = ethsim::apply_board_control(server, line);
  } catch (const Error& e) {
    answer = std::string("error: ") + params::printable(e.what());
  }
  if (!answer.empty()) std::cout << answer << (answer.back() == '\n' ? "" : "\n") << std::flush;
}

}  // namespace

int serve_eth(const SimOptions& sim, const EthServeOptions& o,
              const std::vector<std::string>& startup_control) {
  ethsim::BoardServer server(server_options(sim, o));
  std::optional<ControlFifo> fifo;
  if (!o.control_fifo.empty()) fifo.emplace(o.control_fifo);
  for (const auto& line : startup_control) ethsim::apply_board_control(server, "all " + line);
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
  std::cout << server.address().ip << ":" << server.address().port << std::endl;
  std::cerr << "i20sim: " << server.describe() << " with " << o.channels << " 8I20(s) on SSERIAL port 0"
            << (o.running_host ? ", another host running them" : "") << std::endl;
  for (std::size_t i = 0; i < o.motors.size(); ++i) {
    const auto& where = server.motor_axes()[i];
    std::cerr << "i20sim: motor '" << o.motors[i].name << "' on channel " << where.channel;
    if (where.axis)
      std::cerr << ", its encoder and Halls on the card's axis " << *where.axis << std::endl;
    else
      std::cerr << ", no axis of this card reads its sensors" << std::endl;
  }
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
