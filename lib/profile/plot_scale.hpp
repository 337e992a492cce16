// SPDX-License-Identifier: GPL-2.0-or-later
// Axis arithmetic shared by the SVG and terminal plots.
#pragma once

#include <string>
#include <vector>

#include "profile/step_response.hpp"

namespace i20::profile {

// Tick positions at 1, 2 or 5 times a power of ten, covering [0, max].
std::vector<double> nice_ticks(double max, int about);
// The top of the current axis: room for the peak and the command.
double current_axis_top(const StepResponse& response);
// "12.5", "0.25": short labels for ticks.
std::string tick_label(double value);
// "0.42 ms, overshoot 3.1%, settles in 1.20 ms": the metrics in one line.
std::string metrics_summary(const StepResponse& response);

}  // namespace i20::profile
