// SPDX-License-Identifier: GPL-2.0-or-later
#include "motor/amp_gains.hpp"

#include <numbers>

namespace i20::motor {
namespace {

double omega(double hz) {
  return 2.0 * std::numbers::pi * hz;
}

}  // namespace

double kp_counts_per_unit(double max_current_a, double bus_voltage_v, const ReferenceTuning& ref) {
  const double ref_physical = ref.motor.inductance_h * omega(ref.bandwidth_hz);
  return static_cast<double>(ref.kp) / ref_physical * (max_current_a / ref.max_current_a) *
         (ref.bus_voltage_v / bus_voltage_v);
}

double ki_counts_per_unit(double max_current_a, double bus_voltage_v, const ReferenceTuning& ref) {
  const double ref_physical = ref.motor.resistance_ohm * omega(ref.bandwidth_hz);
  return static_cast<double>(ref.ki) / ref_physical * (max_current_a / ref.max_current_a) *
         (ref.bus_voltage_v / bus_voltage_v);
}

PhysicalGains physical_gains(std::int64_t kp, std::int64_t ki, double max_current_a, double bus_voltage_v,
                             const ReferenceTuning& reference) {
  return {static_cast<double>(kp) / kp_counts_per_unit(max_current_a, bus_voltage_v, reference),
          static_cast<double>(ki) / ki_counts_per_unit(max_current_a, bus_voltage_v, reference)};
}

}  // namespace i20::motor
