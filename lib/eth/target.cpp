// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/target.hpp"

#include <charconv>

#include "error/error.hpp"

namespace i20::eth {
namespace {

constexpr std::string_view kScheme = "eth://";
constexpr const char* kSyntax = "expected eth://IP[:UDPPORT][/portP][/chN], e.g. eth://192.168.1.121/ch0";

std::optional<unsigned long> number(std::string_view text) {
  if (text.empty() || text.size() > 9) return std::nullopt;
  unsigned long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

void require_range(unsigned value, unsigned limit, const char* what) {
  if (value >= limit)
    throw UsageError(std::string(what) + " " + std::to_string(value) + " is out of range (0.." +
                     std::to_string(limit - 1) + ")");
}

// "ch3" -> 3, "port1" -> 1 for the given prefix; nullopt when the prefix differs.
std::optional<unsigned> indexed(std::string_view segment, std::string_view prefix) {
  if (segment.substr(0, prefix.size()) != prefix) return std::nullopt;
  const auto n = number(segment.substr(prefix.size()));
  if (!n)
    throw UsageError("'" + std::string(segment) + "' needs a number after '" + std::string(prefix) + "'; " +
                     kSyntax);
  return static_cast<unsigned>(*n);
}

}  // namespace

void require_ipv4(std::string_view text) {
  unsigned parts = 0;
  std::size_t at = 0;
  while (at <= text.size()) {
    const std::size_t dot = text.find('.', at);
    const std::string_view part =
        text.substr(at, dot == std::string_view::npos ? std::string_view::npos : dot - at);
    const auto n = number(part);
    if (!n || *n > 255 || part.size() > 3) break;
    ++parts;
    if (dot == std::string_view::npos) {
      if (parts == 4) return;
      break;
    }
    at = dot + 1;
  }
  throw UsageError("'" + std::string(text) + "' is not an IPv4 address (expected e.g. 192.168.1.121)");
}

std::string HostPort::describe() const {
  return port == lbp::lbp16::kUdpPort ? ip : ip + ":" + std::to_string(port);
}

HostPort parse_host_port(std::string_view text, std::uint16_t default_port) {
  HostPort out{.ip = std::string(text), .port = default_port};
  if (const auto colon = text.rfind(':'); colon != std::string_view::npos) {
    const auto port = number(text.substr(colon + 1));
    if (!port || *port == 0 || *port > 65535)
      throw UsageError("'" + std::string(text.substr(colon + 1)) + "' is not a UDP port (1..65535)");
    out.ip = std::string(text.substr(0, colon));
    out.port = static_cast<std::uint16_t>(*port);
  }
  require_ipv4(out.ip);
  return out;
}

std::string EthTarget::describe() const {
  std::string s = "eth " + host_port.describe();
  if (sserial_port != 0) s += " port " + std::to_string(sserial_port);
  return s + " ch " + std::to_string(channel);
}

std::string EthTarget::url() const {
  std::string s = std::string(kScheme) + host_port.describe();
  if (sserial_port != 0) s += "/port" + std::to_string(sserial_port);
  return s + "/ch" + std::to_string(channel);
}

bool is_eth_url(std::string_view text) {
  return text.substr(0, kScheme.size()) == kScheme;
}

EthTarget parse_target(std::string_view url) {
  if (!is_eth_url(url)) throw UsageError("'" + std::string(url) + "' is not an Ethernet target; " + kSyntax);
  std::string_view rest = url.substr(kScheme.size());
  const std::size_t slash = rest.find('/');
  EthTarget target{.host_port = parse_host_port(rest.substr(0, slash))};
  bool seen_port = false, seen_channel = false;
  rest = slash == std::string_view::npos ? std::string_view{} : rest.substr(slash + 1);
  while (!rest.empty()) {
    const std::size_t next = rest.find('/');
    const std::string_view segment = rest.substr(0, next);
    rest = next == std::string_view::npos ? std::string_view{} : rest.substr(next + 1);
    if (segment.empty()) continue;
    if (auto ch = indexed(segment, "ch"); ch && !seen_channel) {
      target.channel = *ch;
      seen_channel = true;
    } else if (auto port = indexed(segment, "port"); port && !seen_port && !seen_channel) {
      target.sserial_port = *port;
      seen_port = true;
    } else {
      throw UsageError("unexpected '" + std::string(segment) + "' in '" + std::string(url) + "'; " + kSyntax);
    }
  }
  require_range(target.channel, kMaxChannels, "channel");
  require_range(target.sserial_port, kMaxSserialPorts, "SSERIAL port");
  return target;
}

EthTarget make_target(std::string_view host_port, unsigned channel, unsigned sserial_port) {
  require_range(channel, kMaxChannels, "channel");
  require_range(sserial_port, kMaxSserialPorts, "SSERIAL port");
  return EthTarget{.host_port = parse_host_port(host_port), .sserial_port = sserial_port, .channel = channel};
}

}  // namespace i20::eth
