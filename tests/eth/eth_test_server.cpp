// SPDX-License-Identifier: GPL-2.0-or-later
// Test-only: serves the virtual card until killed (or for --seconds N), so that external
// clients such as mesaflash can be pointed at it by hand.
//   eth_test_server [ADDR[:PORT]] [--card 7i96s|7i92t|7i92t-servo] [--seconds N] [--spin REV_PER_S]
// 7i92t-servo is the 7I92T with four encoder + 8I20 axes (BoardConfig::preset_7i92t_servo).
// --spin turns axis 0's shaft (encoder 2000 counts, index at 0, Halls with 4 pole pairs) at a
// constant speed, for watching hostmot2's encoder and InM pins move.
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
  double spin = 0;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--card" && i + 1 < argc && std::string(argv[i + 1]) == "7i92t-servo") {
        ++i;
        options.card = ethsim::BoardKind::I7i92t;
        options.config = ethsim::BoardConfig::preset_7i92t_servo();
      } else if (arg == "--card" && i + 1 < argc)
        options.card = ethsim::parse_board_kind(argv[++i]);
      else if (arg == "--seconds" && i + 1 < argc)
        seconds = std::stod(argv[++i]);
      else if (arg == "--spin" && i + 1 < argc)
        spin = std::stod(argv[++i]);
      else
        options.listen = ethsim::parse_listen_address(arg);
    }
    if (options.config)
      options.amplifiers = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};
    else if (options.card == ethsim::BoardKind::I7i92t)
      options.amplifiers = {{0, 0}, {0, 3}, {1, 7}};
    ethsim::BoardServer server(options);
    if (spin != 0)
      server.with_card([spin](ethsim::VirtualBoard& board) {
        const auto start = board.board_time();
        board.feedback().connect_axis(0, ethsim::EncoderSpec{.counts_per_turn = 2000},
                                      ethsim::HallSpec{.pole_pairs = 4},
                                      [spin, start](ethsim::Clock::time_point t) {
                                        return spin * std::chrono::duration<double>(t - start).count();
                                      });
      });
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::cout << server.describe() << std::endl;
    if (seconds > 0) {
      server.start();
      const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
      while (!g_stop && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));  // SIGTERM ends it early
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
