// An in-process virtual 8I20 behind the toolkit's usual setup-mode link, opened as an
// ops::Card, with the simulator's own memory as the ground truth: every test judges the
// card by what the simulator holds, never by what the tool reports.
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "link/pipelined_link.hpp"
#include "ops/card.hpp"
#include "params/param_db.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"

namespace i20::ops::testing {

// What the simulated card holds, byte for byte.
struct GroundTruth {
  lbp::Bytes ram;
  lbp::Bytes eeprom;
  lbp::local::NvAccess nv_access = lbp::local::NvAccess::Ram;
  bool rpcmem = false;
  bool powered = true;
};

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
    link::PipelinedLinkOptions link_options;
    link_options.base_timeout = std::chrono::milliseconds(20);
    link_ = std::make_unique<link::PipelinedLink>(std::move(stream), link_options);
  }

  // Opens (identifies) the card over the rig's link; the rig keeps the simulator for the truth.
  std::unique_ptr<Card> open(Cancel cancel = {}) {
    return Card::attach(std::make_unique<Forward>(*link_), parse_endpoint("sim"), loaded_, RetryPolicy{}, cancel);
  }

  std::string control(const std::string& line) { return stream_->control(line); }
  std::int64_t value(const std::string& name) { return std::stoll(control("get " + name)); }

  GroundTruth truth() {
    return stream_->with_card([](sim::Virtual8i20& c) {
      GroundTruth t;
      for (std::uint32_t a = 0; a < 0x10000; ++a) t.ram.push_back(c.amplifier().ram(static_cast<std::uint16_t>(a)));
      const auto e = c.amplifier().eeprom().bytes();
      t.eeprom.assign(e.begin(), e.end());
      t.nv_access = c.lbp_registers().nv_access;
      t.rpcmem = c.lbp_registers().rpcmem;
      t.powered = c.powered();
      return t;
    });
  }
  sim::DeviceStats stats() {
    return stream_->with_card([](sim::Virtual8i20& c) { return c.stats(); });
  }
  const params::ParamDb& loaded() const { return loaded_; }
  sim::RegisterMap map() {
    return stream_->with_card([](sim::Virtual8i20& c) { return c.amplifier().map(); });
  }

  // Every byte that changed between two truths and that nothing explains: not a cell the
  // command named, not a register the card changes itself (FAULT, STATUS, BUSV, TEMPERATURE,
  // CLEARFAULT), and, when the card reset meanwhile, not a working register reloaded from
  // its NV twin or its power-up default. Empty: no stray write.
  std::vector<std::string> unexplained_changes(const GroundTruth& before, const GroundTruth& after,
                                               const std::vector<std::string>& named, bool reset) {
    const auto m = map();
    std::vector<std::string> out;
    const auto is_named = [&](const std::string& n) { return std::ranges::find(named, n) != named.end(); };
    const auto value = [](const lbp::Bytes& mem, const sim::Register& r) {
      std::uint64_t v = 0;
      for (unsigned i = 0; i < r.bytes(); ++i) v |= std::uint64_t{mem[r.address + i]} << (8 * i);
      return v;
    };
    for (std::size_t a = 0; a < after.eeprom.size(); ++a) {
      if (before.eeprom[a] == after.eeprom[a]) continue;
      const sim::Register* r = nullptr;
      for (const auto& reg : m.all())
        if (reg.space == sim::Space::Eeprom && reg.overlaps(static_cast<std::uint32_t>(a), 1)) r = &reg;
      if (!r || !is_named(r->name)) out.push_back("EEPROM byte " + std::to_string(a) + (r ? " (" + r->name + ")" : ""));
    }
    for (std::size_t a = 0; a < after.ram.size(); ++a) {
      if (before.ram[a] == after.ram[a]) continue;
      const sim::Register* r = nullptr;
      for (const auto& reg : m.all())
        if (reg.space == sim::Space::Ram && reg.overlaps(static_cast<std::uint32_t>(a), 1)) r = &reg;
      if (!r) {
        out.push_back("RAM byte " + std::to_string(a) + " (no register)");
        continue;
      }
      static const std::vector<std::string> kVolatile{"FAULT", "STATUS", "BUSV", "TEMPERATURE", "CLEARFAULT"};
      if (is_named(r->name) || std::ranges::find(kVolatile, r->name) != kVolatile.end()) continue;
      if (reset) {
        const sim::Register* nv = r->twin.empty() ? nullptr : m.find(r->twin);
        if (nv && nv->space == sim::Space::Eeprom && value(after.ram, *r) == value(after.eeprom, *nv)) continue;
        if (!nv && r->default_value && value(after.ram, *r) == static_cast<std::uint64_t>(*r->default_value)) continue;
      }
      out.push_back("RAM byte " + std::to_string(a) + " (" + r->name + ")");
    }
    return out;
  }
  link::PipelinedLink& link() { return *link_; }

 private:
  // A Link that forwards to the rig's, so a Card can own "its" link while the rig keeps it.
  class Forward final : public link::Link {
   public:
    explicit Forward(link::Link& to) : to_(to) {}
    std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override { return to_.execute(batch); }
    std::string describe() const override { return to_.describe(); }

   private:
    link::Link& to_;
  };

  RigOptions options_;
  params::ParamDb loaded_ = params::ParamDb::builtin();
  sim::SimStream* stream_ = nullptr;
  std::unique_ptr<link::PipelinedLink> link_;
};

}  // namespace i20::ops::testing
