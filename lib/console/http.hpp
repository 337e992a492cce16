// SPDX-License-Identifier: GPL-2.0-or-later
// The HTTP types the console's pure request handling and its socket code share.
#pragma once

#include <boost/beast/http.hpp>
#include <chrono>
#include <cstddef>
#include <string>

namespace i20::console {

namespace http = boost::beast::http;
using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

// Beast's string views (Boost's own before 1.77) as standard strings.
inline std::string text(boost::beast::string_view s) {
  return std::string(s.data(), s.size());
}

// What one connection may send: a browser page needs far less; anything bigger is refused
// before it is buffered.
struct Limits {
  std::size_t body_bytes = 64 * 1024;   // an edit is a few hundred bytes
  std::size_t header_bytes = 8 * 1024;  // the request line and every header together
  std::size_t header_count = 48;
};

// A complete response: status, the message as text (JSON for /api, plain text elsewhere),
// and the headers every response carries (no caching, no framing, no sniffing).
Response make_response(http::status status, std::string body, const std::string& content_type,
                       const Request& request);
// A refusal in one line a person can act on ("no token: open the URL `i20 console` printed").
Response error_response(http::status status, const std::string& message, const Request& request);

}  // namespace i20::console
