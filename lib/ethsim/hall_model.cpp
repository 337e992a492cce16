// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/hall_model.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "error/error.hpp"

namespace i20::ethsim {

namespace {

double fraction(double turns) {
  return turns - std::floor(turns);
}

}  // namespace

HallSensors::HallSensors(HallSpec spec) : spec_(spec) {
  if (spec_.pole_pairs == 0) throw UsageError("Hall sensors need a motor with at least one pole pair");
  auto sorted = spec_.order;
  std::sort(sorted.begin(), sorted.end());
  if (sorted != std::array<unsigned, 3>{0, 1, 2})
    throw UsageError("the Hall wiring order must name each of the sensors 0, 1, 2 once");
  if (!std::isfinite(spec_.electrical_offset_turns) || !std::isfinite(spec_.first_rise_turns))
    throw UsageError("the Hall sensors' angles are not numbers");
}

double HallSensors::electrical_turns(double mechanical_turns) const {
  return spec_.pole_pairs * mechanical_turns + spec_.electrical_offset_turns;
}

std::array<HallOutput, 3> HallSensors::outputs(double mechanical_turns) const {
  const double spacing = spec_.layout == HallLayout::Spaced120 ? 1.0 / 3.0 : 1.0 / 6.0;
  const double electrical = electrical_turns(mechanical_turns);
  std::array<HallOutput, 3> out{};
  for (unsigned input = 0; input < 3; ++input) {
    const unsigned sensor = spec_.order[input];
    const bool high = fraction(electrical - spec_.first_rise_turns - sensor * spacing) < 0.5;
    const bool level = high != spec_.inverted;
    switch (faults_[input]) {
      case HallFault::None: out[input] = level ? HallOutput::High : HallOutput::Low; break;
      case HallFault::StuckHigh: out[input] = HallOutput::High; break;
      case HallFault::StuckLow: out[input] = HallOutput::Low; break;
      case HallFault::Missing: out[input] = HallOutput::Open; break;
    }
  }
  return out;
}

unsigned HallSensors::code(double mechanical_turns, bool open_reads) const {
  const auto out = outputs(mechanical_turns);
  unsigned code = 0;
  for (const HallOutput o : out) {
    const bool high = o == HallOutput::High || (o == HallOutput::Open && open_reads);
    code = code << 1 | (high ? 1u : 0u);
  }
  return code;
}

void HallSensors::set_fault(unsigned input, HallFault fault) {
  if (input >= 3) throw UsageError("there are three Hall inputs (0-2), not " + std::to_string(input));
  faults_[input] = fault;
}

}  // namespace i20::ethsim
