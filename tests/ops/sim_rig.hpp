// SPDX-License-Identifier: GPL-2.0-or-later
// An in-process virtual 8I20 behind the toolkit's usual setup-mode link, opened as an
// ops::Amp, with the simulator's own memory as the ground truth: every test judges the
// card by what the simulator holds, never by what the tool reports.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "link/pipelined_link.hpp"
#include "ops/core/amp.hpp"
#include "params/param_db.hpp"
#include "sim/ground_truth.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"

namespace i20::ops::testing {

using sim::GroundTruth;

struct RigOptions {
  std::optional<std::uint64_t> random_map;  // another SWREVISION, shuffled RAM addresses
  std::chrono::milliseconds reset_time{1};
  double busv = 320.0;
  bool enable = true;
  std::vector<std::string> overlays;  // YAML texts applied to the loaded database

  RigOptions& map(std::uint64_t seed) { return random_map = seed, *this; }
  RigOptions& reset_ms(int ms) { return reset_time = std::chrono::milliseconds(ms), *this; }
  RigOptions& bus(double volts) { return busv = volts, *this; }
  RigOptions& enable_off() { return enable = false, *this; }
  RigOptions& overlay(std::string yaml) { return overlays.push_back(std::move(yaml)), *this; }
};

class SimRig {
 public:
  explicit SimRig(RigOptions o = {}) : options_(std::move(o)) {
    for (std::size_t i = 0; i < options_.overlays.size(); ++i)
      loaded_.apply_overlay_string(options_.overlays[i], "overlay" + std::to_string(i) + ".yaml");
    sim::SimOptions sim;
    sim.device.map = options_.random_map ? sim::RegisterMap::builtin().shuffled(*options_.random_map)
                                         : sim::register_map_from(loaded_);
    sim.device.reset_time = options_.reset_time;
    sim.device.world.bus_volts = options_.busv;
    sim.device.world.enable = options_.enable;
    auto stream = std::make_unique<sim::SimStream>(std::move(sim));
    stream_ = stream.get();
    const link::PipelinedLinkOptions link_options{.base_timeout = std::chrono::milliseconds(20),
                                                  .retries = 0u,
                                                  .max_drain = std::chrono::milliseconds(500)};
    link_ = std::make_unique<link::PipelinedLink>(std::move(stream), link_options);
  }

  // Opens (identifies) the card over the rig's link; the rig keeps the simulator for the truth.
  std::unique_ptr<Amp> open(Cancel cancel = {}) {
    return Amp::attach(std::make_unique<Forward>(*link_, before_), parse_endpoint("sim"), loaded_,
                       RetryPolicy{}, cancel);
  }
  // Runs before every batch the opened cards send (an injection at the right moment).
  void before_each_batch(std::function<void(std::span<const lbp::Command>)> hook) {
    *before_ = std::move(hook);
  }

  std::string control(const std::string& line) { return stream_->control(line); }
  std::int64_t value(const std::string& name) { return std::stoll(control("get " + name)); }

  GroundTruth truth() {
    return stream_->with_card([](sim::Virtual8i20& c) { return sim::capture(c); });
  }
  sim::DeviceStats stats() {
    return stream_->with_card([](sim::Virtual8i20& c) { return c.stats(); });
  }
  const params::ParamDb& loaded() const { return loaded_; }
  sim::RegisterMap map() {
    return stream_->with_card([](sim::Virtual8i20& c) { return c.amplifier().map(); });
  }

  // Changes nothing explains (lib/sim/ground_truth.hpp): empty means no stray write.
  std::vector<std::string> unexplained_changes(const GroundTruth& before, const GroundTruth& after,
                                               const std::vector<std::string>& named) {
    return sim::unexplained_changes(map(), before, after, named);
  }
  link::PipelinedLink& link() { return *link_; }

 private:
  // A Link that forwards to the rig's, so an ops::Amp can own "its" link while the rig keeps it.
  class Forward final : public link::Link {
   public:
    using Hook = std::function<void(std::span<const lbp::Command>)>;
    Forward(link::Link& to, std::shared_ptr<Hook> before) : to_(to), before_(std::move(before)) {}
    std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override {
      if (*before_) (*before_)(batch);
      return to_.execute(batch);
    }
    std::string describe() const override { return to_.describe(); }

   private:
    link::Link& to_;
    std::shared_ptr<Hook> before_;
  };

  RigOptions options_;
  params::ParamDb loaded_ = params::ParamDb::builtin();
  sim::SimStream* stream_ = nullptr;
  std::unique_ptr<link::PipelinedLink> link_;
  std::shared_ptr<Forward::Hook> before_ = std::make_shared<Forward::Hook>();
};

}  // namespace i20::ops::testing
