// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/world.hpp"

#include <algorithm>
#include <cmath>

namespace i20::sim {
namespace {

std::uint16_t to_raw(double value, double per_count) {
  const double counts = std::round(value / per_count);
  return static_cast<std::uint16_t>(std::clamp(counts, 0.0, 65535.0));
}

}  // namespace

World::World(WorldSettings settings) : settings_(settings), rng_(settings.noise_seed) {}

double World::noise(double amplitude) {
  if (amplitude <= 0) return 0;
  // Raw engine bits keep the sequence identical on every standard library.
  const double unit = static_cast<double>(rng_() >> 11) * 0x1.0p-53;  // [0, 1)
  return (2 * unit - 1) * amplitude;
}

World::Sample World::sample() {
  Sample s;
  s.bus_volts = std::max(0.0, settings_.bus_volts + noise(settings_.bus_noise_volts));
  s.temperature_c = settings_.temperature_c + noise(settings_.temp_noise_c);
  s.busv_raw = to_raw(s.bus_volts, 0.01);
  s.temperature_raw = to_raw(s.temperature_c, 0.01);
  return s;
}

}  // namespace i20::sim
