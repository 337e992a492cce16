// SPDX-License-Identifier: GPL-2.0-or-later
// Who may talk to the console, decided per request before anything else looks at it. The
// console drives a card on a 400 V power stage, so a page the user did not open must not be
// able to reach it:
//  - the token: printed once in the URL; the first `/?token=...` trades it for an HttpOnly,
//    SameSite=Strict cookie and a redirect that drops it from the address bar; every other
//    request needs that cookie;
//  - Host: only the address and port the server listens on (a DNS-rebinding page sends its
//    own name);
//  - Origin: state-changing requests (POST) and WebSocket upgrades must come from the
//    console's own origin (cross-site request forgery, cross-site WebSocket hijacking);
//  - the header count (the sizes are the parser's limits).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "console/http.hpp"

namespace i20::console {

// A fresh token of 128 random bits, as 32 hex digits (std::random_device: the kernel's).
std::string make_token();
// Whether two secrets are equal, in time independent of where they differ, so that a secret
// cannot be guessed a character at a time from response times.
bool same_secret(const std::string& a, const std::string& b);

class Gate {
 public:
  // `authorities`: the Host values this server answers to ("127.0.0.1:8720", and
  // "localhost:8720" on loopback).
  Gate(std::string token, std::vector<std::string> authorities, Limits limits = {});

  // nullopt: the request may go on. Otherwise the response to send instead: a refusal, or
  // the login redirect that sets the cookie.
  std::optional<Response> judge(const Request& request) const;
  // The same for a WebSocket upgrade (Origin is required there).
  std::optional<Response> judge_upgrade(const Request& request) const;

  const std::string& token() const { return token_; }
  static constexpr const char* kCookie = "i20_console";

 private:
  std::optional<Response> judge_common(const Request& request, bool needs_origin) const;
  bool host_allowed(const Request& request) const;
  bool origin_allowed(const Request& request) const;
  bool cookie_valid(const Request& request) const;
  Response login(const Request& request, const std::string& path) const;

  std::string token_;
  std::vector<std::string> authorities_;
  Limits limits_;
};

// The path and the query of a request target ("/a/b?x=1" -> "/a/b", "x=1").
std::pair<std::string, std::string> split_target(const std::string& target);
// The value of `key` in a query string ("token=abc&x=1"), nullopt when absent.
std::optional<std::string> query_value(const std::string& query, const std::string& key);

}  // namespace i20::console
