// SPDX-License-Identifier: GPL-2.0-or-later
// Shared test helpers: a virtual card on an ephemeral loopback port, and a scripted
// "card" whose replies the test writes by hand (wrong sizes, wrong senders, silence).
#pragma once

#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/address_v4.hpp>
#include <boost/asio/ip/udp.hpp>
#include <chrono>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "eth/target.hpp"
#include "ethsim/server.hpp"
#include "eventually.hpp"  // test::eventually, for what the card's server thread does
#include "lbp16/lbp16.hpp"

namespace i20::test {

// A virtual card serving on 127.0.0.1:<ephemeral> for the lifetime of the object.
class RunningBoard {
 public:
  // The defaults are built in a named local (loopback()): a temporary ServerOptions as a
  // default argument makes GCC 12 at -O3 report -Wmaybe-uninitialized, a false positive.
  RunningBoard() : server_(loopback()) { server_.start(); }
  explicit RunningBoard(ethsim::ServerOptions options) : server_(ephemeral(std::move(options))) {
    server_.start();
  }
  eth::HostPort address() const { return server_.address(); }
  eth::EthTarget target(unsigned channel = 0, unsigned sserial_port = 0) const {
    return eth::EthTarget{.host_port = address(), .sserial_port = sserial_port, .channel = channel};
  }
  ethsim::BoardServer& server() { return server_; }
  // The virtual 8I20 on a channel, inside the server's lock.
  template <class F>
  auto with_amplifier(unsigned port, unsigned channel, F&& f) {
    return server_.with_card(
        [&](ethsim::VirtualBoard& board) { return f(*server_.amplifier(board, port, channel)); });
  }

 private:
  // Default options on an ephemeral loopback port.
  static ethsim::ServerOptions loopback() {
    ethsim::ServerOptions o;
    o.listen = eth::HostPort{.ip = "127.0.0.1", .port = 0};
    return o;
  }
  static ethsim::ServerOptions ephemeral(ethsim::ServerOptions o) {
    o.listen = eth::HostPort{.ip = "127.0.0.1", .port = 0};
    return o;
  }
  ethsim::BoardServer server_;
};

// Answers like an LBP16 card that reads zeros everywhere except space 6 Scratch, which
// echoes the value written to it earlier in the packet (the UdpClient's sequence tag).
inline lbp::Bytes zero_card_reply(lbp::ByteView request) {
  namespace lbp16 = lbp::lbp16;
  lbp::Bytes reply;
  std::uint64_t scratch = 0;
  for (const auto& c : lbp16::parse_request(request).commands) {
    const bool is_scratch = c.word.space == lbp16::space::kStatus && c.address == 0x0018;
    if (c.word.write && is_scratch) scratch = lbp::read_le(c.data);
    if (!c.word.write) lbp::append_le(reply, is_scratch ? scratch : 0, c.reply_bytes());
  }
  return reply;
}

// A card whose behaviour the test scripts. It owns two sockets on 127.0.0.1: the card's
// own and an impostor, so a script can answer from the wrong address too.
class ScriptedBoard {
 public:
  using udp = boost::asio::ip::udp;
  struct Sockets {
    udp::socket& card;
    udp::socket& impostor;
  };
  using Script = std::function<void(const lbp::Bytes& request, const udp::endpoint& client, Sockets sockets)>;

  explicit ScriptedBoard(Script script) : script_(std::move(script)) {
    for (udp::socket* s : {&card_, &impostor_}) {
      s->open(udp::v4());
      s->bind(udp::endpoint(boost::asio::ip::make_address_v4("127.0.0.1"), 0));
      s->non_blocking(true);
    }
    thread_ = std::thread([this] { loop(); });
  }
  ~ScriptedBoard() {
    stop_ = true;
    thread_.join();
  }
  std::uint16_t port() const { return card_.local_endpoint().port(); }
  std::size_t requests() const {
    std::lock_guard lock(mutex_);
    return requests_.size();
  }
  std::vector<lbp::Bytes> request_log() const {
    std::lock_guard lock(mutex_);
    return requests_;
  }

 private:
  void loop() {
    lbp::Bytes buffer(2048);
    while (!stop_) {
      boost::system::error_code ec;
      udp::endpoint client;
      const std::size_t n = card_.receive_from(boost::asio::buffer(buffer), client, 0, ec);
      if (ec) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
      const lbp::Bytes request(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(n));
      {
        std::lock_guard lock(mutex_);
        requests_.push_back(request);
      }
      script_(request, client, Sockets{card_, impostor_});
    }
  }

  Script script_;
  boost::asio::io_context io_;
  udp::socket card_{io_};
  udp::socket impostor_{io_};
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::vector<lbp::Bytes> requests_;
  std::thread thread_;
};

}  // namespace i20::test
