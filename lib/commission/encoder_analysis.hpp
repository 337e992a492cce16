// SPDX-License-Identifier: GPL-2.0-or-later
// The encoder half of the analysis: direction, counts per electrical turn, pole pairs or
// counts per turn, and the index's electrical angle (bldc's encoder-offset).
#pragma once

#include <cstdint>
#include <optional>
#include <span>

#include "commission/result.hpp"
#include "commission/sample.hpp"
#include "commission/sweep.hpp"

namespace i20::commission {

// The rotor's electrical angle as the encoder tells it, once the analysis has calibrated it.
struct RotorAngleFromEncoder {
  double reference_count = 0;                    // the index, or count 0 without one
  double signed_counts_per_electrical_turn = 0;  // negative when counts fall going forward
  double angle_at_reference_turns = 0;
  double uncertainty_turns = 0;
  // How much the rotor wanders about the command sample to sample (cogging, vibration): it
  // moves Hall edges about by as much.
  double jitter_turns = 0;
  double rotor_turns(std::int64_t count) const {
    return angle_at_reference_turns +
           (static_cast<double>(count) - reference_count) / signed_counts_per_electrical_turn;
  }
};

// Fills the encoder findings and problems of `result`; returns the calibrated angle when the
// encoder followed the command (even if some value, such as the pole pairs, stays unknown).
std::optional<RotorAngleFromEncoder> analyse_encoder(std::span<const Sample> samples, const Sweep& sweep,
                                                     const AnalysisOptions& options,
                                                     CommutationResult& result);

}  // namespace i20::commission
