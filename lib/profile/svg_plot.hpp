// SPDX-License-Identifier: GPL-2.0-or-later
// The step response as a standalone SVG image (plain text, no external resources): axes
// with labels, a grid, the command and the response, rise time and overshoot marked.
#pragma once

#include <string>

#include "profile/step_response.hpp"

namespace i20::profile {

struct SvgOptions {
  int width = 720;
  int height = 420;
  std::string title = "Current step response";
};

std::string step_response_svg(const StepResponse& response, const SvgOptions& options = {});

}  // namespace i20::profile
