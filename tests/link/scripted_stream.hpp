// SPDX-License-Identifier: GPL-2.0-or-later
// An in-process ByteStream that plays an 8I20: it cuts what the link writes into
// commands with lbp::CommandSplitter, answers them from a FakeCard, and can be told to
// misbehave (corrupt, drop, delay, add bytes). It also watches the link: every write()
// call, unanswered command bytes, and writes made while a barrier is unanswered.
#pragma once

#include <chrono>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <thread>

#include "fake_lbp_memory.hpp"
#include "lbp/command.hpp"
#include "lbp/preparse.hpp"
#include "link/byte_stream.hpp"

namespace i20::link::fake {

struct Script {
  FakeCard card;
  unsigned baud = 115200;
  std::string name = "/dev/fake0";
  std::size_t chunk = std::numeric_limits<std::size_t>::max();  // bytes per read_some at most

  // Misbehaviour, keyed by the index of the command as the device counts them.
  std::set<std::size_t> corrupt;                                    // reply CRC flipped
  std::size_t mute_from = std::numeric_limits<std::size_t>::max();  // no replies from here on
  std::size_t ignore_next = 0;                             // drop this many commands, then answer again
  std::map<std::size_t, std::chrono::milliseconds> delay;  // reply delayed
  // Reply split: the first `bytes` go at once, the rest after `after`.
  struct Tail {
    std::size_t bytes;
    std::chrono::milliseconds after;
  };
  std::map<std::size_t, Tail> late_tail;
  std::map<std::size_t, lbp::Bytes> extra;  // bytes sent right after the reply

  // Observations.
  std::vector<lbp::Bytes> writes;    // one entry per write() call
  std::vector<lbp::Bytes> commands;  // commands as the device cut them (without CRC)
  std::size_t bad_command_crcs = 0;
  std::size_t unanswered = 0;  // wire bytes of commands whose reply the host has not read
  std::size_t max_unanswered = 0;
  bool barrier_open = false;  // a barrier command's reply is not read yet
  std::size_t writes_during_barrier = 0;
  std::size_t discards = 0;

  // Puts bytes on the line as if the card sent them unasked.
  void inject(lbp::ByteView bytes) {
    for (auto b : bytes) output.push_back({b, std::chrono::steady_clock::now(), 0, false, false});
  }

  struct OutByte {
    lbp::Byte value;
    std::chrono::steady_clock::time_point ready;
    std::size_t command_wire = 0;  // on a reply's last byte: the command's wire size
    bool ends_reply = false;
    bool ends_barrier = false;
  };
  std::deque<OutByte> output;
};

class ScriptedStream final : public ByteStream {
 public:
  explicit ScriptedStream(std::shared_ptr<Script> script) : s_(std::move(script)) {}

  void write(lbp::ByteView bytes) override {
    s_->writes.emplace_back(bytes.begin(), bytes.end());
    if (s_->barrier_open) ++s_->writes_during_barrier;
    splitter_.push(bytes);
    for (;;) {
      auto next = splitter_.next({});
      if (next.status != lbp::CommandSplitter::Status::Frame) break;
      handle(next.frame);
    }
  }

  std::size_t read_some(std::span<lbp::Byte> buffer, Clock::time_point deadline) override {
    for (;;) {
      const auto now = Clock::now();
      if (!s_->output.empty() && s_->output.front().ready <= now) return take(buffer, now);
      if (now >= deadline) return 0;
      auto wake = deadline;
      if (!s_->output.empty()) wake = std::min(wake, s_->output.front().ready);
      std::this_thread::sleep_until(wake);
    }
  }

  void discard_input() override {
    ++s_->discards;
    const auto now = Clock::now();
    while (!s_->output.empty() && s_->output.front().ready <= now)
      consume(s_->output.front()), s_->output.pop_front();
  }

  unsigned baud() const override { return s_->baud; }
  std::string name() const override { return s_->name; }

 private:
  void handle(const lbp::CommandSplitter::Frame& frame) {
    const auto index = s_->commands.size();
    s_->commands.push_back(frame.command);
    const auto wire_size = frame.command.size() + 1;
    s_->unanswered += wire_size;
    s_->max_unanswered = std::max(s_->max_unanswered, s_->unanswered);
    if (!frame.crc_ok) ++s_->bad_command_crcs;
    if (index >= s_->mute_from) return;
    if (s_->ignore_next > 0) {
      --s_->ignore_next;
      s_->unanswered -= wire_size;
      return;
    }
    auto data = s_->card.answer(frame.command);
    if (!data) return;
    auto reply = FakeCard::wire(*data);
    if (s_->corrupt.count(index)) reply.back() ^= 0xFF;
    const bool barrier = is_barrier(frame.command);
    if (barrier) s_->barrier_open = true;
    auto ready = Clock::now();
    if (auto d = s_->delay.find(index); d != s_->delay.end()) ready += d->second;
    for (std::size_t i = 0; i < reply.size(); ++i) {
      if (auto t = s_->late_tail.find(index); t != s_->late_tail.end() && i == t->second.bytes)
        ready += t->second.after;
      const bool last = i + 1 == reply.size();
      s_->output.push_back({reply[i], ready, last ? wire_size : 0, last, last && barrier});
    }
    if (auto e = s_->extra.find(index); e != s_->extra.end())
      for (auto b : e->second) s_->output.push_back({b, ready, 0, false, false});
  }

  // The tests mark the reset and EEPROM-style writes as barriers; the device recognises
  // them by their bytes (a reset, or any write to the NV window at 0x8000 and up).
  static bool is_barrier(const lbp::Bytes& command) {
    if (command == lbp::reset_processor().bytes) return true;
    return lbp::kind_of(command[0]) == lbp::CommandKind::Data && lbp::DataHeader::decode(command[0]).write &&
           lbp::DataHeader::decode(command[0]).has_address && command[2] >= 0x80;
  }

  std::size_t take(std::span<lbp::Byte> buffer, Clock::time_point now) {
    std::size_t n = 0;
    while (n < buffer.size() && n < s_->chunk && !s_->output.empty() && s_->output.front().ready <= now) {
      buffer[n++] = s_->output.front().value;
      consume(s_->output.front());
      s_->output.pop_front();
    }
    return n;
  }

  void consume(const Script::OutByte& b) {
    if (b.ends_reply) s_->unanswered -= b.command_wire;
    if (b.ends_barrier) s_->barrier_open = false;
  }

  std::shared_ptr<Script> s_;
  lbp::CommandSplitter splitter_;
};

}  // namespace i20::link::fake
