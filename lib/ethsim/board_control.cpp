// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/board_control.hpp"

#include <charconv>
#include <sstream>
#include <vector>

#include "sim/control.hpp"
#include "sim/error.hpp"

namespace i20::ethsim {
namespace {

const char* kHelp =
    "ch N LINE                  the same line for the 8I20 on channel N of port 0, e.g. ch 2 busv 24\n"
    "channel N LINE             the same\n"
    "port P ch N LINE           the 8I20 on SSERIAL port P channel N (7I92T)\n"
    "all LINE                   every 8I20, e.g. all enable off\n"
    "amplifiers                 which channels have an 8I20\n"
    "host on [PERIOD_MS] [port P]   another host (a LinuxCNC stand-in) runs the 8I20s in normal mode\n"
    "host off                   that host exits: it stops its port\n"
    "host                       what the host is doing\n"
    "card reset [MS]            the card resets: silent MS ms (default 5), SSERIAL ports come back stopped\n"
    "card power-loss MS         the card and its 8I20s lose power for MS ms, then power up\n"
    "card loss RATE [SEED]      datagrams to the card lost, 0..1 (a bad cable or switch), e.g. card loss "
    "0.02\n";

std::vector<std::string> words(std::string_view line) {
  std::istringstream in{std::string(line)};
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// The text after the first `skip` words of `line`.
std::string_view rest_after(std::string_view line, std::size_t skip) {
  std::size_t at = 0;
  for (std::size_t i = 0; i < skip; ++i) {
    at = line.find_first_not_of(" \t", at);
    at = line.find_first_of(" \t", at);
    if (at == std::string_view::npos) return {};
  }
  const auto begin = line.find_first_not_of(" \t", at);
  return begin == std::string_view::npos ? std::string_view{} : line.substr(begin);
}

unsigned number(const std::string& text, const char* what, const char* form) {
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size())
    throw sim::ControlError("'" + text + "' is not a " + what + " number; expected " + form);
  return value;
}

// A probability, 0..1.
double rate(const std::string& text, const char* form) {
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size() || !(value >= 0 && value <= 1))
    throw sim::ControlError("'" + text + "' is not a rate from 0 to 1; expected " + form);
  return value;
}

std::string on_amplifier(BoardServer& server, ChannelAddress where, std::string_view line) {
  if (line.empty())
    throw sim::ControlError("nothing to do for port " + std::to_string(where.port) + " ch " +
                            std::to_string(where.channel) + "; expected e.g. ch 2 busv 24");
  return server.with_card([&](VirtualBoard& board) {
    auto* amp = server.amplifier(board, where.port, where.channel);
    if (!amp)
      throw sim::ControlError("no 8I20 on SSERIAL port " + std::to_string(where.port) + " channel " +
                              std::to_string(where.channel) + " (see: amplifiers)");
    return sim::apply_control(*amp, line, Clock::now());
  });
}

ChannelAddress first_amplifier(const BoardServer& server) {
  const auto list = server.amplifiers();
  return list.empty() ? ChannelAddress{0, 0} : list.front();
}

std::string host_control(BoardServer& server, const std::vector<std::string>& w) {
  const char* form = "host on [PERIOD_MS] [port P] | host off | host";
  if (w.size() == 1) {
    const auto status = server.host_status();
    return status ? "host: " + *status : "host: none (the card is idle)";
  }
  if (w[1] == "off") {
    server.stop_host();
    return "ok";
  }
  if (w[1] != "on") throw sim::ControlError("unknown host command '" + w[1] + "'; expected " + form);
  HostOptions options;
  for (std::size_t i = 2; i < w.size(); ++i) {
    if (w[i] == "port" && i + 1 < w.size()) {
      options.port = number(w[++i], "port", form);
    } else {
      const unsigned ms = number(w[i], "period", form);
      if (ms == 0 || ms > 20) throw sim::ControlError("host period " + w[i] + " ms: use 1..20 ms");
      options.period = std::chrono::milliseconds(ms);
    }
  }
  try {
    server.start_host(options);
  } catch (const Error& e) {
    throw sim::ControlError(e.what());
  }
  return "ok: " + *server.host_status();
}

}  // namespace

std::string board_control_help() {
  return kHelp;
}

std::string apply_board_control(BoardServer& server, std::string_view line) {
  const auto w = words(line.substr(0, line.find('#')));
  if (w.empty()) return "";
  const std::string& head = w[0];
  if (head == "ch" || head == "channel") {
    if (w.size() < 2) throw sim::ControlError("expected ch N LINE, e.g. ch 2 busv 24");
    return on_amplifier(server, {0, number(w[1], "channel", "ch N LINE")}, rest_after(line, 2));
  }
  if (head == "port") {
    if (w.size() < 4 || (w[2] != "ch" && w[2] != "channel"))
      throw sim::ControlError("expected port P ch N LINE, e.g. port 1 ch 5 temp 60");
    return on_amplifier(
        server, {number(w[1], "port", "port P ch N LINE"), number(w[3], "channel", "port P ch N LINE")},
        rest_after(line, 4));
  }
  if (head == "all") {
    const auto rest = rest_after(line, 1);
    std::string answers;
    for (const auto& a : server.amplifiers()) {
      if (!answers.empty()) answers += "; ";
      // append(), not "p" + ...: GCC 12 -O3 reports a false -Wrestrict inside operator+
      answers.append("p").append(std::to_string(a.port)).append("c");
      answers.append(std::to_string(a.channel)).append(": ").append(on_amplifier(server, a, rest));
    }
    return answers.empty() ? "no 8I20 on this card" : answers;
  }
  if (head == "amplifiers") {
    std::string s;
    for (const auto& a : server.amplifiers())
      s += (s.empty() ? "" : ", ") + std::string("port ") + std::to_string(a.port) + " ch " +
           std::to_string(a.channel);
    return s.empty() ? "no 8I20 on this card" : "8I20s on " + s;
  }
  if (head == "host") return host_control(server, w);
  if (head == "card") {
    const char* form = "card reset [MS] | card power-loss MS | card loss RATE [SEED]";
    if (w.size() >= 2 && w[1] == "reset") {
      server.go_dark(std::chrono::milliseconds(w.size() > 2 ? number(w[2], "time", form) : 5), false);
      return "ok";
    }
    if (w.size() == 3 && w[1] == "power-loss") {
      server.go_dark(std::chrono::milliseconds(number(w[2], "time", form)), true);
      return "ok";
    }
    if ((w.size() == 3 || w.size() == 4) && w[1] == "loss") {
      server.set_datagram_loss(rate(w[2], form), w.size() == 4 ? number(w[3], "seed", form) : 1u);
      return "ok";
    }
    throw sim::ControlError(std::string("expected ") + form);
  }
  if (head == "help") return board_control_help() + sim::control_help();
  return on_amplifier(server, first_amplifier(server), line);
}

}  // namespace i20::ethsim
