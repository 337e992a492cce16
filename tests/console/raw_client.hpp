// SPDX-License-Identifier: GPL-2.0-or-later
// A raw HTTP client over a real socket for the console's tests: the request is sent byte for
// byte as written (no client library normalises "/../" or fills in a Host), and the reply
// is read until the server closes.
#pragma once

#include <string>

namespace i20::console::testing {

// The parts appended in order (GCC 12's -O3 warns on `"literal" + std::string&&`).
template <class... Parts>
std::string cat(const Parts&... parts) {
  std::string s;
  ((s += parts), ...);
  return s;
}

struct Reply {
  int status = 0;  // 0: no reply at all
  std::string head;
  std::string body;
  std::string header(const std::string& name) const;  // "" when absent
};

// Sends `request` to 127.0.0.1:port and reads the reply until the server closes, or, when
// `until` is given, until the bytes received hold it (a WebSocket stays open); 5 s at most.
Reply ask(unsigned short port, const std::string& request, const std::string& until = "");

// "GET /path HTTP/1.1" with Host 127.0.0.1:port, Connection: close, and `extra` header lines
// ("Cookie: ...\r\n").
std::string get_request(unsigned short port, const std::string& target, const std::string& extra = "");
// A POST with the console's own Origin unless `extra` gives headers instead.
std::string post_request(unsigned short port, const std::string& target, const std::string& body,
                         const std::string& extra);

}  // namespace i20::console::testing
