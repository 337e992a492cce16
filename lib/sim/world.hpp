// SPDX-License-Identifier: GPL-2.0-or-later
// The physical world around the simulated card: motor bus voltage, card temperature,
// the enable input and fault causes that only hardware could produce (over-current,
// module, serial line errors). Tests and the i20sim control channel change it at will.
#pragma once

#include <cstdint>
#include <random>

namespace i20::sim {

struct WorldSettings {
  double bus_volts = 320.0;      // the manual's RPD BUSV example: 32000 = 320 V
  double temperature_c = 35.0;   // a warm bench
  bool enable = true;            // enable input driven (no NOENABLEFAULT)
  double bus_noise_volts = 0.0;  // +- uniform noise on every BUSV sample
  double temp_noise_c = 0.0;     // +- uniform noise on every TEMPERATURE sample
  std::uint64_t noise_seed = 1;
  // FAULT bits held active as if the hardware detected them (e.g. fault::kOverCurrent).
  std::uint16_t forced_faults = 0;
};

class World {
 public:
  struct Sample {
    double bus_volts = 0;
    double temperature_c = 0;
    std::uint16_t busv_raw = 0;         // 10 mV units
    std::uint16_t temperature_raw = 0;  // 0.01 C units
  };

  explicit World(WorldSettings settings = {});

  WorldSettings& settings() { return settings_; }
  const WorldSettings& settings() const { return settings_; }
  // Restarts the noise sequence (after changing the seed).
  void reseed() { rng_.seed(settings_.noise_seed); }

  // One measurement, noise included.
  Sample sample();

 private:
  double noise(double amplitude);

  WorldSettings settings_;
  std::mt19937_64 rng_;
};

}  // namespace i20::sim
