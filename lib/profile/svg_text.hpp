// SPDX-License-Identifier: GPL-2.0-or-later
// The text both plots write into SVG: labels escaped for XML, coordinates to a tenth of a
// pixel.
#pragma once

#include <cstdio>
#include <string>

namespace i20::profile {

inline std::string xml_escaped(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

inline std::string svg_coordinate(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

}  // namespace i20::profile
