// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/simulated_host.hpp"

#include <algorithm>
#include <thread>

#include "hostmot2/hostmot2.hpp"
#include "lbp/bytes.hpp"

namespace i20::ethsim {

namespace lbp16 = lbp::lbp16;
namespace sslbp = lbp::hm2::sslbp;

namespace {

// A register's value from its reply bytes.
constexpr auto word = lbp::read_le32;

}  // namespace

SimulatedHost::SimulatedHost(HostOptions options) : options_(options) {
  if (options_.mask == 0) options_.mask = 0x01;
}

std::vector<lbp::Bytes> SimulatedHost::send(VirtualBoard& board, const std::vector<lbp16::Command>& packet,
                                            Clock::time_point now) {
  ++stats_.packets;
  const auto reply = board.handle(lbp16::encode_packet(packet), now);
  if (!reply) return std::vector<lbp::Bytes>(packet.size());
  return lbp16::split_reply(packet, *reply);
}

std::uint32_t SimulatedHost::command_register(VirtualBoard& board, Clock::time_point now) {
  const std::uint16_t address = board.sserial_registers(options_.port).command;
  return word(send(board, {lbp16::read_hm2(address)}, now).front()) & 0xFFFF;
}

void SimulatedHost::run_until(VirtualBoard& board, Clock::time_point now) {
  if (now < next_ || state_ == State::Stopped) return;
  const auto regs = board.sserial_registers(options_.port);
  switch (state_) {
    case State::Stopping:
      send(board, {lbp16::write_hm2(regs.command, sslbp::stop()), lbp16::read_hm2(regs.command)}, now);
      state_ = State::Starting;
      break;
    case State::Starting:
      if (command_register(board, now) != 0) break;  // stop or start still running: poll
      if (start_issued_) {
        state_ = State::Running;
        break;
      }
      send(board, {lbp16::write_hm2(regs.command, sslbp::start_normal(options_.mask))}, now);
      start_issued_ = true;
      break;
    case State::Running: {
      std::vector<lbp16::Command> cycle{lbp16::read_hm2(regs.command), lbp16::read_hm2(regs.data)};
      for (unsigned ch = 0; ch < 8; ++ch)
        if (options_.mask & (1u << ch)) {
          cycle.push_back(lbp16::read_hm2(regs.interface0(ch)));
          cycle.push_back(lbp16::read_hm2(regs.interface1(ch)));
          cycle.push_back(
              lbp16::write_hm2(regs.interface0(ch), options_.interface0 ? options_.interface0(ch) : 0u));
        }
      cycle.push_back(lbp16::write_hm2(regs.command, sslbp::doit(options_.mask)));
      const auto parts = send(board, cycle, now);
      if ((word(parts[0]) & 0xFFFF) != 0) ++stats_.late_cycles;
      if ((word(parts[1]) & options_.mask) != 0 && stats_.cycles > 0) ++stats_.failed_cycles;
      ++stats_.cycles;
      if (last_doit_) stats_.longest_gap = std::max(stats_.longest_gap, now - *last_doit_);
      last_doit_ = now;
      break;
    }
    case State::Stopped: break;
  }
  next_ = now + (state_ == State::Running ? options_.period : std::chrono::microseconds(200));
}

void SimulatedHost::stop(VirtualBoard& board, Clock::time_point now) {
  if (state_ == State::Stopped) return;
  const auto regs = board.sserial_registers(options_.port);
  // SSLBP ignores a command written while it is busy (8I20 manual, "DOIT": COMMAND reads
  // non-zero until done), so the host waits out its last DOIT first, then its stop, as a
  // host that exits cleanly does. Bounded: a card held in reset never reads idle.
  const auto wait_idle = [&] {
    const auto limit = Clock::now() + std::chrono::milliseconds(200);
    while (command_register(board, std::max(now, Clock::now())) != 0 && Clock::now() < limit)
      std::this_thread::sleep_for(std::chrono::microseconds(100));
  };
  wait_idle();
  send(board, {lbp16::write_hm2(regs.command, sslbp::stop()), lbp16::read_hm2(regs.command)},
       std::max(now, Clock::now()));
  wait_idle();
  state_ = State::Stopped;
}

std::string SimulatedHost::describe() const {
  std::string s = "normal mode on SSERIAL port " + std::to_string(options_.port) + " ch";
  for (unsigned ch = 0; ch < 8; ++ch)
    if (options_.mask & (1u << ch)) s.append(" ").append(std::to_string(ch));  // GCC 12 -Wrestrict in Release
  const auto us = std::chrono::duration_cast<std::chrono::microseconds>(options_.period).count();
  s += ", every " + (us % 1000 == 0 ? std::to_string(us / 1000) + " ms" : std::to_string(us) + " us");
  s += ", " + std::to_string(stats_.cycles) + " DOITs (" + std::to_string(stats_.failed_cycles) + " failed)";
  const auto gap_ms = std::chrono::duration_cast<std::chrono::milliseconds>(stats_.longest_gap).count();
  s += ", longest gap " + std::to_string(gap_ms) + " ms";
  if (state_ == State::Stopped) s += ", stopped";
  return s;
}

}  // namespace i20::ethsim
