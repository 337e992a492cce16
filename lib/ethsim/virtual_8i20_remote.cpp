// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/virtual_8i20_remote.hpp"

#include <algorithm>

#include "lbp/bytes.hpp"

namespace i20::ethsim {
namespace {

// Events the device may raise while we wait for one reply (timeouts, EEPROM, delayed
// replies); more than this means it is stuck, and the exchange ends.
constexpr unsigned kMaxEventSteps = 256;

}  // namespace

sim::DeviceOptions Virtual8i20Remote::default_options() {
  sim::DeviceOptions o;
  o.mode = sim::FramingMode::Operate;
  o.amplifier.watchdog_set_by_host = true;  // SSLBP's normal start sets it (8I20 DEVICE SPECIFIC SETUP)
  return o;
}

Virtual8i20Remote::Virtual8i20Remote(sim::DeviceOptions options, Clock::time_point power_on)
    : device_(std::move(options), power_on) {}

Exchange Virtual8i20Remote::exchange(lbp::ByteView framed_command, std::size_t reply_wire_bytes,
                                     Clock::time_point now, Clock::duration timeout) {
  const auto character = device_.character_time();
  // The last command byte reaches the card after the whole command has been shifted out.
  Clock::time_point t = now + character * static_cast<long>(framed_command.size());
  device_.receive(framed_command, t);
  lbp::Bytes reply = device_.take_output();
  const auto deadline = t + timeout;
  for (unsigned step = 0; reply.size() < reply_wire_bytes && step < kMaxEventSteps; ++step) {
    const auto next = device_.next_event();
    if (!next || *next > deadline) break;
    t = std::max(t, *next);
    device_.advance(t);
    const lbp::Bytes more = device_.take_output();
    reply.insert(reply.end(), more.begin(), more.end());
  }
  if (reply.size() < reply_wire_bytes) t = std::max(t, deadline);
  return Exchange{.reply = std::move(reply), .done = t + character * static_cast<long>(reply_wire_bytes)};
}

void Virtual8i20Remote::advance(Clock::time_point now) {
  device_.advance(now);
  device_.take_output();
}

std::vector<lbp::Command> Virtual8i20Remote::normal_start_commands() const {
  const auto& map = device_.amplifier().map();
  return {lbp::write(map.at("CLEARFAULT").address, lbp::DataSize::Two, 1),
          lbp::write(map.at("QSETPOINT").address, lbp::DataSize::Two, 0)};
}

void Virtual8i20Remote::normal_started() {
  device_.amplifier().set_watchdog_by_host();
}

std::string Virtual8i20Remote::describe() const {
  return "8I20 unit " + lbp::hex_value(device_.amplifier().value("UNITNUMBER"), 8);
}

}  // namespace i20::ethsim
