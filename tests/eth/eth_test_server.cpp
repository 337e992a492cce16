// SPDX-License-Identifier: GPL-2.0-or-later
// Test-only: serves the virtual card until killed (or for --seconds N), so that external
// clients such as mesaflash can be pointed at it by hand.
//   eth_test_server [ADDR[:PORT]] [--card 7i96s|7i92t] [--seconds N]
#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <string>
#include <thread>

#include "ethsim/server.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop = true;
}
}  // namespace

int main(int argc, char** argv) {
  using namespace i20;
  ethsim::ServerOptions options;
  double seconds = 0;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--card" && i + 1 < argc)
        options.card = ethsim::parse_card_kind(argv[++i]);
      else if (arg == "--seconds" && i + 1 < argc)
        seconds = std::stod(argv[++i]);
      else
        options.listen = ethsim::parse_listen_address(arg);
    }
    if (options.card == ethsim::CardKind::I7i92t) options.amplifiers = {{0, 0}, {0, 3}, {1, 7}};
    ethsim::CardServer server(options);
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::cout << server.describe() << std::endl;
    if (seconds > 0) {
      server.start();
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
      server.stop();
    } else {
      server.run(&g_stop);
    }
  } catch (const std::exception& e) {
    std::cerr << "eth_test_server: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
