// SPDX-License-Identifier: GPL-2.0-or-later
#include "raw_client.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>

namespace i20::console::testing {
namespace {

struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

}  // namespace

std::string Reply::header(const std::string& name) const {
  const std::string key = cat("\r\n", lower(name), ":");
  const auto low = lower(head);
  const auto at = low.find(key);
  if (at == std::string::npos) return "";
  const auto start = head.find_first_not_of(' ', at + key.size());
  return head.substr(start, head.find("\r\n", start) - start);
}

Reply ask(unsigned short port, const std::string& request, const std::string& until) {
  Fd s{::socket(AF_INET, SOCK_STREAM, 0)};
  timeval timeout{5, 0};
  ::setsockopt(s.fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(s.fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return {};
  std::size_t sent = 0;
  while (sent < request.size()) {
    const auto n = ::send(s.fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;  // the server may refuse before it has read everything
    sent += static_cast<std::size_t>(n);
  }
  std::string data;
  char buffer[4096];
  // A deadline for the whole reply: a WebSocket that was wrongly accepted keeps sending.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (std::chrono::steady_clock::now() < deadline) {
    const auto n = ::recv(s.fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    data.append(buffer, static_cast<std::size_t>(n));
    if (!until.empty() && data.find(until) != std::string::npos) break;
  }
  Reply reply;
  const auto end = data.find("\r\n\r\n");
  if (data.rfind("HTTP/1.1 ", 0) != 0 || end == std::string::npos) return reply;  // no reply
  reply.status = std::stoi(data.substr(9, 3));
  reply.head = data.substr(0, end);
  reply.body = data.substr(end + 4);
  return reply;
}

std::string get_request(unsigned short port, const std::string& target, const std::string& extra) {
  std::string r = "GET ";
  r += target;
  r += " HTTP/1.1\r\nHost: 127.0.0.1:";
  r += std::to_string(port);
  r += "\r\nConnection: close\r\n";
  r += extra;
  r += "\r\n";
  return r;
}

std::string post_request(unsigned short port, const std::string& target, const std::string& body,
                         const std::string& extra) {
  std::string r = "POST ";
  r += target;
  r += " HTTP/1.1\r\nHost: 127.0.0.1:";
  r += std::to_string(port);
  r += "\r\nConnection: close\r\nContent-Type: text/plain\r\nContent-Length: ";
  r += std::to_string(body.size());
  r += "\r\n";
  r += extra;
  r += "\r\n";
  r += body;
  return r;
}

}  // namespace i20::console::testing
