// SPDX-License-Identifier: GPL-2.0-or-later
#include "console/gate.hpp"

#include <algorithm>
#include <random>

namespace i20::console {

bool same_secret(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

namespace {

std::string trimmed(std::string_view s) {
  while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
  while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
  return std::string(s);
}

bool is_state_changing(http::verb method) {
  return method != http::verb::get;
}

}  // namespace

Response make_response(http::status status, std::string body, const std::string& content_type,
                       const Request& request) {
  Response res{status, request.version()};
  res.set(http::field::server, "i20-console");
  res.set(http::field::content_type, content_type);
  res.set(http::field::cache_control, "no-store");
  res.set("X-Content-Type-Options", "nosniff");
  res.set("X-Frame-Options", "DENY");
  res.set("Referrer-Policy", "no-referrer");
  res.set("Content-Security-Policy",
          "default-src 'self'; connect-src 'self'; img-src 'self' data: blob:; frame-ancestors 'none'");
  res.keep_alive(request.keep_alive());
  res.body() = std::move(body);
  res.prepare_payload();
  return res;
}

Response error_response(http::status status, const std::string& message, const Request& request) {
  std::string body = "i20 console: ";
  body += message;
  body += "\n";
  auto res = make_response(status, std::move(body), "text/plain; charset=utf-8", request);
  res.keep_alive(false);  // a refused client starts again on a fresh connection
  return res;
}

std::string make_token() {
  std::random_device device;
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (int i = 0; i < 4; ++i) {
    const auto word = static_cast<std::uint32_t>(device());
    for (int shift = 28; shift >= 0; shift -= 4) token += kHex[(word >> shift) & 0xF];
  }
  return token;
}

std::pair<std::string, std::string> split_target(const std::string& target) {
  const auto q = target.find('?');
  if (q == std::string::npos) return {target, ""};
  return {target.substr(0, q), target.substr(q + 1)};
}

std::optional<std::string> query_value(const std::string& query, const std::string& key) {
  std::size_t start = 0;
  while (start <= query.size()) {
    const auto end = std::min(query.find('&', start), query.size());
    const std::string_view pair(query.data() + start, end - start);
    const auto eq = pair.find('=');
    if (pair.substr(0, eq) == key)
      return eq == std::string_view::npos ? "" : std::string(pair.substr(eq + 1));
    start = end + 1;
  }
  return std::nullopt;
}

Gate::Gate(std::string token, std::vector<std::string> authorities, Limits limits)
    : token_(std::move(token)), authorities_(std::move(authorities)), limits_(limits) {}

bool Gate::host_allowed(const Request& request) const {
  const auto host = request.find(http::field::host);
  if (host == request.end()) return false;
  const std::string value = trimmed(text(host->value()));
  return std::find(authorities_.begin(), authorities_.end(), value) != authorities_.end();
}

bool Gate::origin_allowed(const Request& request) const {
  const auto origin = request.find(http::field::origin);
  if (origin == request.end()) return false;
  const std::string value = trimmed(text(origin->value()));
  return std::any_of(authorities_.begin(), authorities_.end(),
                     [&](const std::string& a) { return value == "http://" + a; });
}

bool Gate::cookie_valid(const Request& request) const {
  for (const auto& field : request) {
    if (field.name() != http::field::cookie) continue;
    const std::string cookies = text(field.value());
    std::size_t start = 0;
    while (start < cookies.size()) {
      const auto end = std::min(cookies.find(';', start), cookies.size());
      const std::string pair = trimmed(std::string_view(cookies).substr(start, end - start));
      const auto eq = pair.find('=');
      if (eq != std::string::npos && pair.substr(0, eq) == kCookie &&
          same_secret(pair.substr(eq + 1), token_))
        return true;
      start = end + 1;
    }
  }
  return false;
}

Response Gate::login(const Request& request, const std::string& path) const {
  auto res = make_response(http::status::see_other, "", "text/plain; charset=utf-8", request);
  res.set(http::field::location, path.empty() ? "/" : path);
  std::string cookie = kCookie;
  cookie += "=";
  cookie += token_;
  cookie += "; Path=/; HttpOnly; SameSite=Strict";
  res.set(http::field::set_cookie, cookie);
  return res;
}

std::optional<Response> Gate::judge_common(const Request& request, bool needs_origin) const {
  if (static_cast<std::size_t>(std::distance(request.begin(), request.end())) > limits_.header_count) {
    std::string message = "too many header fields (at most ";
    message += std::to_string(limits_.header_count);
    message += ")";
    return error_response(http::status::request_header_fields_too_large, message, request);
  }
  if (!host_allowed(request))
    return error_response(http::status::misdirected_request,
                          "the Host header does not name this console's address and port (a page served "
                          "under another name cannot use it)",
                          request);
  if (needs_origin && !origin_allowed(request))
    return error_response(http::status::forbidden,
                          "refused: the request does not come from the console's own page (Origin header)",
                          request);
  const std::string target = text(request.target());
  const auto [path, query] = split_target(target);
  if (const auto given = query_value(query, "token")) {
    if (!same_secret(*given, token_))
      return error_response(http::status::forbidden, "wrong token: open the URL `i20 console` printed",
                            request);
    if (request.method() == http::verb::get && !needs_origin) return login(request, path);
    return std::nullopt;
  }
  if (!cookie_valid(request))
    return error_response(http::status::unauthorized,
                          "no token: open the URL `i20 console` printed (it carries the token of this run)",
                          request);
  return std::nullopt;
}

std::optional<Response> Gate::judge(const Request& request) const {
  const auto method = request.method();
  if (method != http::verb::get && method != http::verb::post)
    return error_response(http::status::method_not_allowed, "only GET and POST are served", request);
  return judge_common(request, is_state_changing(method));
}

std::optional<Response> Gate::judge_upgrade(const Request& request) const {
  return judge_common(request, true);
}

}  // namespace i20::console
