// SPDX-License-Identifier: GPL-2.0-or-later
// The commutation analysis: from the samples of an align-and-sweep run (hold, N electrical
// turns forward, N back) to the encoder direction, counts per electrical turn, pole pairs,
// the index's electrical angle (bldc's encoder-offset) and the Hall map.
//
// Method (docs/commissioning-analysis.md): like ODrive and VESC, sweep both ways so the
// friction lag (the rotor trails the command) cancels in the mean; the counts per electrical
// turn come from a straight-line fit of count against command on each sweep; angles are
// averaged as unit vectors; Hall edges are averaged over both directions (cancels sensor
// hysteresis) against the rotor angle the encoder gives (cancels lag and cogging).
#pragma once

#include <span>

#include "commission/result.hpp"
#include "commission/sample.hpp"

namespace i20::commission {

CommutationResult analyse(std::span<const Sample> samples, const AnalysisOptions& options = {});

}  // namespace i20::commission
