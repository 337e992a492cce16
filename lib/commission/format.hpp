// SPDX-License-Identifier: GPL-2.0-or-later
// Numbers in the analysis' one-line explanations.
#pragma once

#include <cstdio>
#include <string>

namespace i20::commission {

inline std::string fixed(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, value);
  return text;
}

}  // namespace i20::commission
