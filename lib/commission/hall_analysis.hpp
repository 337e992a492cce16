// SPDX-License-Identifier: GPL-2.0-or-later
// The Hall half of the analysis: each sensor's health, each state's electrical angle, each
// edge's angle, the sequence (bldc's pattern), the layout (60 or 120 degrees).
#pragma once

#include <optional>
#include <span>

#include "commission/encoder_analysis.hpp"
#include "commission/result.hpp"
#include "commission/sample.hpp"
#include "commission/sweep.hpp"

namespace i20::commission {

// With the encoder's calibrated angle the Hall edges are placed where the rotor really was;
// without it, against the command (the forward/backward average still cancels the lag).
void analyse_hall(std::span<const Sample> samples, const Sweep& sweep,
                  const std::optional<RotorAngleFromEncoder>& encoder, const AnalysisOptions& options,
                  CommutationResult& result);

}  // namespace i20::commission
