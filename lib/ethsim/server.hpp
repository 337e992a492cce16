// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual card on the network: a UDP server that answers LBP16 like a 7I96S (or a
// 7I92T) with virtual 8I20s behind its SSERIAL channels. Real clients work against it
// unchanged: this toolkit, mesaflash, LinuxCNC's hm2_eth.
//
//   ethsim::ServerOptions options;                 // 127.0.0.1:27181, 7I96S, 8I20 on ch 0
//   options.listen = eth::parse_host_port("127.0.0.2:27181");
//   ethsim::BoardServer server(options);            // binds now: errors surface here
//   server.start();                                // background thread ...
//   server.stop();                                 // ... or server.run(&flag) in this one
//
// The server replies from its bound address to the sender's address and port. A packet
// that wrote WaituS is answered only when the card's clock has caught up, as the real
// card would. Between packets the card's time keeps running (every `tick`), so SSLBP
// chatters and the 8I20s' watchdogs bite on time.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "eth/target.hpp"
#include "ethsim/board_config.hpp"
#include "ethsim/simulated_host.hpp"
#include "ethsim/virtual_board.hpp"
#include "motor/params.hpp"
#include "sim/virtual_8i20.hpp"

namespace i20::ethsim {

struct ChannelAddress {
  unsigned port = 0;
  unsigned channel = 0;
  bool operator==(const ChannelAddress&) const = default;
};

struct ServerOptions {
  // Where to listen. Port 0 picks a free one (tests); the cards use 27181.
  eth::HostPort listen{.ip = "127.0.0.1", .port = lbp::lbp16::kUdpPort};
  BoardKind card = BoardKind::I7i96s;
  // Replaces the preset of `card` when set (tests: other versions, no timer space, ...).
  std::optional<BoardConfig> config{};
  // Channels with a virtual 8I20 (port = SSERIAL instance). Unit numbers count up from
  // amplifier.amplifier.unit_number in this order; an EEPROM file gets a "-pPcC" suffix
  // when there is more than one amplifier.
  std::vector<ChannelAddress> amplifiers{{0, 0}};
  sim::DeviceOptions amplifier = sim::DeviceOptions{};  // mode is forced to operate (see below)
  bool operate_mode = true;  // the 8I20s' W6 jumper: a running machine is in operate mode
  SslbpConfig sslbp{};
  // Replaces `amplifiers` entirely when set (tests put scripted remotes here).
  RemoteFactory remotes{};
  // Card time granularity between packets.
  std::chrono::milliseconds tick{2};
  // Another host already running the machine when the server starts (see
  // simulated_host.hpp); start_host() starts one later.
  std::optional<HostOptions> host{};
  // Motors on the 8I20s of SSERIAL port 0, each on its `channel` (which must hold an 8I20).
  // The card's axis for that channel (BoardConfig::axes) reads the motor's encoder and Halls
  // (ethsim/motor_feedback.hpp).
  std::vector<motor::MotorParams> motors{};
};

struct MotorAxis {
  unsigned channel = 0;            // the 8I20 on SSERIAL port 0 driving the motor
  std::optional<unsigned> axis{};  // the card axis reading its sensors; none: no feedback
};

// "ADDR[:PORT]" (default port 27181; port 0 picks a free one). Throws UsageError.
eth::HostPort parse_listen_address(std::string_view text);

class BoardServer {
 public:
  // Builds the card and binds the socket. Throws Error naming the address when the port
  // is taken or the address is not local.
  explicit BoardServer(ServerOptions options);
  ~BoardServer();
  BoardServer(const BoardServer&) = delete;
  BoardServer& operator=(const BoardServer&) = delete;

  // Serves on a background thread until stop().
  void start();
  // Serves on the calling thread until stop() or until *stop_flag becomes true (a signal
  // handler may set it); checked every tick.
  void run(const std::atomic<bool>* stop_flag = nullptr);
  void stop();

  eth::HostPort address() const;  // the bound address, port 0 resolved
  std::string describe() const;   // "virtual 7I96S at 127.0.0.1:40000"

  // Runs `f` on the card while the server holds it still (inspect or change the 8I20s).
  template <class F>
  auto with_card(F&& f) {
    std::lock_guard lock(mutex_);
    return f(*board_);
  }

  // The virtual 8I20 on a channel, when the server built it (nullptr otherwise). Use it
  // inside with_card().
  sim::Virtual8i20* amplifier(VirtualBoard& board, unsigned port, unsigned channel);
  // The channels the server put 8I20s on (empty when ServerOptions::remotes built them).
  std::vector<ChannelAddress> amplifiers() const {
    return options_.remotes ? std::vector<ChannelAddress>{} : options_.amplifiers;
  }
  // Where ServerOptions::motors went: one entry per motor, in that order.
  const std::vector<MotorAxis>& motor_axes() const { return motor_axes_; }

  // Another host starts running the machine (a stand-in for LinuxCNC). `mask` 0 means the
  // port's 8I20s. Replaces a host already running.
  void start_host(HostOptions options);
  // That host exits: it stops its port, as LinuxCNC does.
  void stop_host();
  // "normal mode on SSERIAL port 0 ch 0, every 1 ms, ..." or nullopt without a host.
  std::optional<std::string> host_status();
  std::optional<HostStats> host_stats();
  bool host_running();

  // The card resets (power_loss false: its 8I20s keep their power) or loses power with
  // them, and answers nothing for `dark`; then its SSERIAL ports come back stopped and the
  // 8I20s power up from their EEPROMs. A host running the card stops with it.
  void go_dark(Clock::duration dark, bool power_loss);
  // Waits until the card has come back from go_dark (its ports stopped, its 8I20s powered up
  // again): false if it has not within `timeout`. True at once for a card that is not dark.
  bool wait_until_back(Clock::duration timeout);

  // Datagrams to the card are lost with probability `rate` (0..1), as on a bad cable or a
  // busy switch: the card never sees them, so each costs its sender the reply. The losses
  // follow `seed`, so a run can be repeated.
  void set_datagram_loss(double rate, std::uint32_t seed);

 private:
  struct Socket;
  void serve_once(std::chrono::steady_clock::time_point until);
  void attach_motors();

  ServerOptions options_;
  std::unique_ptr<Socket> socket_;
  std::mutex mutex_;
  std::unique_ptr<VirtualBoard> board_;
  std::vector<MotorAxis> motor_axes_;
  std::optional<SimulatedHost> host_;            // under mutex_
  std::optional<Clock::time_point> dark_until_;  // under mutex_
  std::condition_variable back_;                 // dark_until_ cleared
  bool power_lost_ = false;                      // under mutex_
  double loss_rate_ = 0;                         // under mutex_
  std::mt19937 loss_rng_;                        // under mutex_
  std::atomic<bool> stop_requested_{false};
  std::thread thread_;
};

}  // namespace i20::ethsim
