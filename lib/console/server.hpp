// SPDX-License-Identifier: GPL-2.0-or-later
// The console's socket side (Boost.Beast, one thread): accepts connections on the address it
// is given (127.0.0.1 unless the user asks otherwise), reads requests within the limits,
// hands each to the Router, and pushes the Api's live samples to WebSocket clients at an
// interval. One thread means one request at a time: one transaction at a time per card.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "console/http.hpp"

namespace i20::console {

class Api;

struct ServerOptions {
  std::string address = "127.0.0.1";
  unsigned short port = 0;  // 0: a free port the system picks
  std::filesystem::path static_dir;
  Limits limits;
  std::chrono::milliseconds live_interval{100};
  std::string token;  // empty: a fresh random one
};

class Server {
 public:
  // Binds and listens at once (throws boost::system::system_error: address in use, ...).
  Server(ServerOptions options, Api& api);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  unsigned short port() const;
  const std::string& token() const;
  // "http://127.0.0.1:8720/?token=...": the one URL that opens the console.
  std::string url() const;
  // Serves until stop() is called or `stop_requested` returns true (polled every 50 ms).
  void run(const std::function<bool()>& stop_requested = {});
  // From any thread.
  void stop();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

// "127.0.0.1:8720", "[::1]:8720": the Host header a browser sends for this address.
std::string authority(const std::string& address, unsigned short port);

}  // namespace i20::console
