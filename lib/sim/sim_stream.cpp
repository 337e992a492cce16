// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/sim_stream.hpp"

#include "sim/control.hpp"

namespace i20::sim {

SimStream::SimStream(SimOptions options)
    : name_(options.name),
      card_(std::make_unique<Virtual8i20>(std::move(options.device), Clock::now())),
      model_(*card_, options.wire) {}

void SimStream::write(lbp::ByteView bytes) {
  {
    std::lock_guard lock(mutex_);
    model_.host_write(bytes, Clock::now());
  }
  changed_.notify_all();
}

std::size_t SimStream::read_some(std::span<lbp::Byte> buffer, link::Clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  for (;;) {
    const auto now = Clock::now();
    model_.pump(now);
    if (const std::size_t n = model_.host_read(buffer, now); n > 0 || buffer.empty()) return n;
    if (now >= deadline) return 0;
    auto wake = deadline;
    if (const auto next = model_.next_wake(); next && *next < wake) wake = *next;
    changed_.wait_until(lock, wake);
  }
}

void SimStream::discard_input() {
  std::lock_guard lock(mutex_);
  const auto now = Clock::now();
  model_.pump(now);
  model_.discard_host_input(now);
}

unsigned SimStream::baud() const {
  std::lock_guard lock(mutex_);
  return card_->baud();
}

std::vector<std::string> SimStream::notes() const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> notes{"in-process simulator, SWREVISION 0x" + [&] {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%04X", card_->amplifier().map().swrevision());
    return std::string(buf);
  }()};
  if (model_.options().emulate_wire_time) notes.push_back("wire-time emulation on");
  return notes;
}

std::string SimStream::control(const std::string& line) {
  std::string answer;
  {
    std::lock_guard lock(mutex_);
    const auto now = Clock::now();
    model_.pump(now);
    answer = apply_control(*card_, line, now);
  }
  changed_.notify_all();
  return answer;
}

std::unique_ptr<link::ByteStream> make_sim_stream(SimOptions options) {
  return std::make_unique<SimStream>(std::move(options));
}

std::unique_ptr<link::PipelinedLink> make_sim_link(SimOptions options,
                                                   link::PipelinedLinkOptions link_options) {
  return std::make_unique<link::PipelinedLink>(make_sim_stream(std::move(options)), link_options);
}

}  // namespace i20::sim
