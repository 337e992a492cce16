// SPDX-License-Identifier: GPL-2.0-or-later
// The console's request handling without sockets: the gate first, then /api/ to the app's
// Api (which calls lib/ops), anything else to the static pages. The server (server.hpp)
// only moves bytes; tests call this directly too.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "console/gate.hpp"
#include "console/http.hpp"

namespace i20::console {

// What the console serves about a card: implemented by the app over lib/ops, so the server
// holds no policy of its own.
class Api {
 public:
  virtual ~Api() = default;
  // A request under /api/ that passed the gate.
  virtual Response handle(const Request& request) = 0;
  // One live sample as a JSON text, pushed to every WebSocket client of /api/live.
  virtual std::string live_sample() = 0;
};

inline constexpr const char* kLivePath = "/api/live";

class Router {
 public:
  Router(Gate gate, std::filesystem::path static_dir, Api& api)
      : gate_(std::move(gate)), static_dir_(std::move(static_dir)), api_(&api) {}

  Response handle(const Request& request);
  // nullopt: the WebSocket upgrade may be accepted; otherwise the refusal to send.
  std::optional<Response> admit_upgrade(const Request& request) const;

  Api& api() { return *api_; }
  const Gate& gate() const { return gate_; }

 private:
  Response serve_static(const Request& request, const std::string& path) const;

  Gate gate_;
  std::filesystem::path static_dir_;
  Api* api_;  // the app's; outlives the server
};

}  // namespace i20::console
