// SPDX-License-Identifier: GPL-2.0-or-later
// The step response as a few lines of text for a terminal: the current as a bar chart of
// block characters, the command level marked, and the metrics in one line.
#pragma once

#include <string>

#include "profile/step_response.hpp"

namespace i20::profile {

struct TextPlotOptions {
  int width = 60;       // plot columns
  int height = 8;       // plot rows
  bool unicode = true;  // eighth blocks and box lines; false: ASCII only
};

std::string step_response_text(const StepResponse& response, const TextPlotOptions& options = {});

}  // namespace i20::profile
