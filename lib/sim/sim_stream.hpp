// SPDX-License-Identifier: GPL-2.0-or-later
// The simulator as a link::ByteStream, in process: write() feeds the virtual card,
// read_some() returns its replies, honouring deadlines and (optionally) wire time.
// With PipelinedLink on top it is the toolkit's `--sim` link.
//
// Thread-safe: one thread may drive the stream while another changes the simulated
// world through with_card() or control().
#pragma once

#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>

#include "link/byte_stream.hpp"
#include "link/link.hpp"
#include "link/pipelined_link.hpp"
#include "sim/virtual_8i20.hpp"
#include "sim/wire_model.hpp"

namespace i20::sim {

struct SimOptions {
  DeviceOptions device{};
  WireOptions wire{};
  std::string name = "simulator";
};

class SimStream final : public link::ByteStream {
 public:
  explicit SimStream(SimOptions options = {});

  void write(lbp::ByteView bytes) override;
  std::size_t read_some(std::span<lbp::Byte> buffer, link::Clock::time_point deadline) override;
  void discard_input() override;
  unsigned baud() const override;
  std::string name() const override { return name_; }
  std::vector<std::string> notes() const override;

  // Runs `f(card)` under the stream's lock, with the card brought up to now first.
  template <typename F>
  auto with_card(F&& f) {
    std::lock_guard lock(mutex_);
    model_.pump(Clock::now());
    return std::forward<F>(f)(*card_);
  }
  // Applies a control line ("busv 400", see control.hpp) and returns its answer.
  std::string control(const std::string& line);

 private:
  std::string name_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::unique_ptr<Virtual8i20> card_;
  WireModel model_;
};

// The in-process simulator as a byte stream (for PipelinedLink or raw-byte tests).
std::unique_ptr<link::ByteStream> make_sim_stream(SimOptions options = {});
// The in-process simulator behind the toolkit's usual setup-mode link.
std::unique_ptr<link::PipelinedLink> make_sim_link(SimOptions options,
                                                   link::PipelinedLinkOptions link_options);

}  // namespace i20::sim
