// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/endpoint.hpp"

#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "error/error.hpp"
#include "eth/passthrough_link.hpp"
#include "eth/passthrough_port.hpp"
#include "eth/target.hpp"
#include "link/pipelined_link.hpp"
#include "link/serial_link.hpp"
#include "ops/core/timing.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"

namespace i20::ops {
namespace {

bool starts_with(const std::string& text, const std::string& prefix) {
  return text.rfind(prefix, 0) == 0;
}

// Same device through different names (a /dev/serial/by-id link and its ttyUSBn) is one line.
std::string canonical_path(const std::string& path) {
  std::error_code ec;
  const auto resolved = std::filesystem::weakly_canonical(path, ec);
  return ec ? path : resolved.string();
}

// WPD/RPD users write COM1; on Linux that is /dev/ttyS0 (a 3I22 shows up as ttyUSBn).
std::optional<std::string> com_port_path(const std::string& text) {
  if (text.size() < 4 || (text.rfind("COM", 0) != 0 && text.rfind("com", 0) != 0)) return std::nullopt;
  unsigned n = 0;
  for (std::size_t i = 3; i < text.size(); ++i) {
    if (text[i] < '0' || text[i] > '9' || n > 255) return std::nullopt;
    n = n * 10 + static_cast<unsigned>(text[i] - '0');
  }
  if (n == 0) return std::nullopt;
  return "/dev/ttyS" + std::to_string(n - 1);
}

Endpoint eth_endpoint(const eth::EthTarget& target, std::string text) {
  Endpoint e;
  e.kind = Endpoint::Kind::Eth;
  e.text = std::move(text);
  e.eth_url = target.url();
  e.eth = target;
  // The channels of one Ethernet card share its UDP port and its SSLBP engine: one line.
  e.line_key = "eth:" + target.host_port.describe();
  return e;
}

Endpoint sim_endpoint(std::string eeprom, std::size_t index) {
  Endpoint e;
  e.kind = Endpoint::Kind::Sim;
  e.path = std::move(eeprom);
  e.text = e.path.empty() ? "sim" : "sim:" + e.path;
  e.line_key = e.path.empty() ? "sim#" + std::to_string(index) : "sim:" + canonical_path(e.path);
  return e;
}

Endpoint serial_endpoint(const std::string& text) {
  Endpoint e;
  e.kind = Endpoint::Kind::Serial;
  e.text = text;
  e.path = com_port_path(text).value_or(text);
  e.line_key = "port:" + canonical_path(e.path);
  return e;
}

}  // namespace

const char* const kEndpointForms =
    "/dev/ttyUSB0 (serial port), COM1 (= /dev/ttyS0), sim (built-in simulator), sim:FILE (simulator with its "
    "EEPROM in FILE), eth://IP/chN (Ethernet card channel)";

std::string Endpoint::flags() const {
  switch (kind) {
    case Kind::Sim: return path.empty() ? "--sim" : "--sim --sim-eeprom " + path;
    case Kind::Eth: return "--port " + eth_url;
    case Kind::Serial: return "--port " + text;
  }
  return {};
}

Endpoint parse_endpoint(const std::string& text, std::size_t index) {
  if (text.empty()) throw UsageError(std::string("empty target; use one of: ") + kEndpointForms);
  if (text == "sim") return sim_endpoint({}, index);
  if (starts_with(text, "sim:")) {
    if (text.size() == 4) throw UsageError("target 'sim:' needs an EEPROM file: sim:card.eeprom");
    return sim_endpoint(text.substr(4), index);
  }
  if (eth::is_eth_url(text)) return eth_endpoint(eth::parse_target(text), text);
  if (text.find("://") != std::string::npos)
    throw UsageError("target '" + text + "': unknown scheme; use one of: " + kEndpointForms);
  return serial_endpoint(text);
}

std::optional<Endpoint> endpoint_from(const TargetFlags& f) {
  const int given = int(f.sim) + int(!f.port.empty()) + int(!f.eth.empty());
  if (given > 1) throw UsageError("name one 8I20: --port, --sim or --eth, not several");
  if (f.sim) return sim_endpoint(f.sim_eeprom, 0);
  if (!f.eth.empty()) {
    const auto target = eth::is_eth_url(f.eth) ? eth::parse_target(f.eth)
                                               : eth::make_target(f.eth, f.channel, f.sserial_port);
    return eth_endpoint(target, target.url());
  }
  if (!f.port.empty()) return parse_endpoint(f.port);
  return std::nullopt;
}

Endpoint require_endpoint(const TargetFlags& flags) {
  if (auto e = endpoint_from(flags)) return *e;
  throw UsageError(
      "no 8I20 given: use --port /dev/ttyUSB0 (see `i20 ports`; COMPORT works too), --sim for the built-in "
      "simulator, or --eth IP for an 8I20 behind a 7I96S/7I92T");
}

std::vector<Endpoint> resolve_endpoints(const std::vector<std::string>& texts,
                                        const std::optional<Endpoint>& global) {
  if (global && !texts.empty())
    throw UsageError("give the cards either with --target or with --port/--sim/--eth, not both");
  if (global) return {*global};
  std::vector<Endpoint> out;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < texts.size(); ++i) {
    auto e = parse_endpoint(texts[i], i);
    // Ethernet targets share a line per card, so for them a repeat is the same URL twice.
    if (!seen.insert(e.is_eth() ? "url:" + e.eth_url : e.line_key).second)
      throw UsageError("target '" + texts[i] + "' is given twice (or names the same card as another target)");
    out.push_back(std::move(e));
  }
  if (out.empty())
    throw UsageError(std::string("no 8I20 given: use --target (") + kEndpointForms +
                     "), or --port/--sim/--eth");
  return out;
}

std::unique_ptr<link::Link> open_link(const Endpoint& e, const params::ParamDb& db, const LinkSettings& s) {
  return open_link(e, db, s, RetryPolicy{});
}

std::unique_ptr<link::Link> open_link(const Endpoint& e, const params::ParamDb& db, const LinkSettings& s,
                                      const RetryPolicy& retry) {
  const link::PipelinedLinkOptions link_options = timing::serial_link(s, retry);
  switch (e.kind) {
    case Endpoint::Kind::Sim: {
      sim::SimOptions sim;
      sim.device.map = sim::register_map_from(db);
      if (!e.path.empty()) sim.device.eeprom_file = e.path;
      sim.name = "the built-in simulator";
      auto stream = std::make_unique<sim::SimStream>(std::move(sim));
      for (const auto& line : s.sim_control) stream->control(line);
      return std::make_unique<link::PipelinedLink>(std::move(stream), link_options);
    }
    case Endpoint::Kind::Eth: {
      return eth::SslbpPassthroughLink::open(e.eth_target(), timing::passthrough(s, retry));
    }
    case Endpoint::Kind::Serial: {
      return link::open_serial_link(e.path, link_options, timing::serial_port(s));
    }
  }
  throw UsageError("unknown target kind");
}

const eth::EthTarget& Endpoint::eth_target() const {
  if (!eth) throw std::logic_error("Endpoint::eth_target: " + text + " is not an Ethernet target");
  return *eth;
}

std::vector<std::vector<std::size_t>> group_by_line(const std::vector<Endpoint>& targets, bool with_eth) {
  std::vector<std::vector<std::size_t>> groups;
  std::map<std::string, std::size_t> group_of;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    if (targets[i].is_eth() && !with_eth) continue;
    const auto [it, fresh] = group_of.try_emplace(targets[i].line_key, groups.size());
    if (fresh) groups.emplace_back();
    groups[it->second].push_back(i);
  }
  return groups;
}

}  // namespace i20::ops
