// SPDX-License-Identifier: GPL-2.0-or-later
// Several channels on one time axis, as a standalone SVG (plain text, no external resources)
// and as CSV: one strip per quantity, each with its own scale, stacked over a shared time
// axis, so that no line hides another and each unit reads off its own ticks (what halscope
// shows a technician, without halscope). Used for a simulated move (i20 pid --svg) and
// whatever else records channels over time.
#pragma once

#include <string>
#include <vector>

namespace i20::profile {

struct ChartSeries {
  std::string label;
  std::vector<double> values;  // one per time sample; not a number: a gap (nothing there)
};

struct ChartStrip {
  std::string title;  // "Position", "Following error"
  std::string unit;   // "mm", "um", "A"
  std::vector<ChartSeries> series;
};

struct StripChart {
  std::string title;
  std::vector<double> time_s;
  std::vector<ChartStrip> strips;
};

// Throws UsageError when a series' length differs from the time axis's, or there is no time.
std::string strip_chart_svg(const StripChart& chart, int width = 900, int strip_height = 170);

// "time_s,Position: command (mm),..." then one row per sample.
std::string strip_chart_csv(const StripChart& chart);

}  // namespace i20::profile
