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
#include "link/given.hpp"

namespace i20::console {

class Api;

// The console's waits, given by the program (ops/core/timing.hpp holds i20's).
struct ServerTiming {
  link::Given<std::chrono::milliseconds> live_interval;  // between two live samples
  link::Given<std::chrono::milliseconds> stop_poll;      // how often run() asks stop_requested
  link::Given<std::chrono::milliseconds> drain;          // reading what a refused client still sends
  link::Given<std::chrono::seconds> idle;  // a connection that sends nothing this long is closed
};

struct ServerOptions {
  ServerTiming timing;
  std::string address = "127.0.0.1";
  unsigned short port = 0;  // 0: a free port the system picks
  std::filesystem::path static_dir{};
  Limits limits{};
  std::string token{};  // empty: a fresh random one
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
  // Serves until stop() is called or `stop_requested` returns true (polled every timing.stop_poll).
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
