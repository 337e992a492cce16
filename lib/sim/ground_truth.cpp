// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/ground_truth.hpp"

#include <algorithm>
#include <array>

namespace i20::sim {
namespace {

const Register* register_at(const RegisterMap& map, Space space, std::size_t address) {
  for (const auto& r : map.all())
    if (r.space == space && r.overlaps(static_cast<std::uint32_t>(address), 1)) return &r;
  return nullptr;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::ranges::find(names, name) != names.end();
}

// Registers the card writes itself, whatever the host does.
constexpr std::array<const char*, 5> kVolatile{"FAULT", "STATUS", "BUSV", "TEMPERATURE", "CLEARFAULT"};

bool volatile_register(const std::string& name) {
  return std::ranges::any_of(kVolatile, [&](const char* v) { return name == v; });
}

}  // namespace

GroundTruth capture(const Virtual8i20& card) {
  GroundTruth t;
  t.ram.resize(0x10000);
  for (std::uint32_t a = 0; a < 0x10000; ++a) t.ram[a] = card.amplifier().ram(static_cast<std::uint16_t>(a));
  const auto e = card.amplifier().eeprom().bytes();
  t.eeprom.assign(e.begin(), e.end());
  t.nv_access = card.lbp_registers().nv_access;
  t.rpcmem = card.lbp_registers().rpcmem;
  t.powered = card.powered();
  t.resets = card.stats().resets;
  t.quiet_since_reset = t.resets > 0 && card.stats().bytes_received == card.stats().bytes_received_at_reset;
  return t;
}

std::uint64_t value_in(const GroundTruth& truth, const Register& reg) {
  const auto& mem = reg.space == Space::Eeprom ? truth.eeprom : truth.ram;
  std::uint64_t v = 0;
  for (unsigned i = 0; i < reg.bytes() && reg.address + i < mem.size(); ++i)
    v |= std::uint64_t{mem[reg.address + i]} << (8 * i);
  return v;
}

bool reloaded_by_reset(const RegisterMap& map, const Register& r, const GroundTruth& after) {
  const Register* nv = r.twin.empty() ? nullptr : map.find(r.twin);
  if (nv && nv->space == Space::Eeprom) return value_in(after, r) == value_in(after, *nv);
  return r.default_value && value_in(after, r) == static_cast<std::uint64_t>(*r.default_value);
}

// The reset came between the writes: the NV twin held its value from before them.
bool reloaded_by_reset(const RegisterMap& map, const Register& r, const GroundTruth& before,
                       const GroundTruth& after) {
  const Register* nv = r.twin.empty() ? nullptr : map.find(r.twin);
  return nv && nv->space == Space::Eeprom && value_in(after, r) == value_in(before, *nv);
}

std::vector<std::string> unexplained_changes(const RegisterMap& map, const GroundTruth& before,
                                             const GroundTruth& after,
                                             const std::vector<std::string>& named) {
  std::vector<std::string> out;
  const bool reset = after.resets != before.resets;
  for (std::size_t a = 0; a < after.eeprom.size() && a < before.eeprom.size(); ++a) {
    if (before.eeprom[a] == after.eeprom[a]) continue;
    const Register* r = register_at(map, Space::Eeprom, a);
    if (!r || !contains(named, r->name))
      out.push_back("EEPROM byte " + std::to_string(a) + (r ? " (" + r->name + ")" : ""));
  }
  for (std::size_t a = 0; a < after.ram.size(); ++a) {
    if (before.ram[a] == after.ram[a]) continue;
    const Register* r = register_at(map, Space::Ram, a);
    if (!r) {
      out.push_back("RAM byte " + std::to_string(a) + " (no register)");
      continue;
    }
    if (contains(named, r->name) || volatile_register(r->name)) continue;
    if (reset && reloaded_by_reset(map, *r, after)) continue;
    if (reset && reloaded_by_reset(map, *r, before, after)) continue;
    out.push_back("RAM byte " + std::to_string(a) + " (" + r->name + ")");
  }
  return out;
}

std::vector<std::string> crossed_thresholds(const RegisterMap& map, const GroundTruth& truth) {
  constexpr std::pair<const char*, const char*> kPairs[] = {{"BRAKEOFFV", "BRAKEONV"},
                                                            {"BUSUNDERV", "BUSOVERV"},
                                                            {"NVBRAKEOFFV", "NVBRAKEONV"},
                                                            {"NVBUSUNDERV", "NVBUSOVERV"}};
  std::vector<std::string> out;
  for (const auto& [low, high] : kPairs) {
    const Register* lo = map.find(low);
    const Register* hi = map.find(high);
    if (!lo || !hi) continue;
    const auto l = value_in(truth, *lo), h = value_in(truth, *hi);
    if (l >= h)
      out.push_back(std::string(low) + " " + std::to_string(l) + " >= " + high + " " + std::to_string(h));
  }
  return out;
}

}  // namespace i20::sim
