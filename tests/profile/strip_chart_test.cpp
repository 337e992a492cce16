// SPDX-License-Identifier: GPL-2.0-or-later
// Several channels on one time axis (profile/strip_chart.hpp): each strip scaled to its own
// data, a peak kept however many samples share a pixel, labels escaped, CSV with a header and
// one row per sample, and inconsistent data refused.
#include "profile/strip_chart.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "error/error.hpp"

using namespace i20::profile;

namespace {

StripChart two_strips(std::size_t samples) {
  StripChart c{"A <test> & chart",
               {},
               {{"Position", "mm", {{"command", {}}, {"encoder", {}}}}, {"Error", "um", {{"e", {}}}}}};
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * 1e-3;
    c.time_s.push_back(t);
    c.strips[0].series[0].values.push_back(10 * std::sin(t));
    c.strips[0].series[1].values.push_back(10 * std::sin(t - 0.001));
    c.strips[1].series[0].values.push_back(k == samples / 2 ? 500.0 : 0.01 * std::sin(100 * t));  // one spike
  }
  return c;
}

// The polylines' y coordinates, per polyline.
std::vector<std::vector<double>> ys(const std::string& svg) {
  std::vector<std::vector<double>> out;
  const std::regex line("points=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), line); it != std::sregex_iterator(); ++it) {
    out.emplace_back();
    const std::string points = (*it)[1];
    const std::regex pair("[-0-9.]+,([-0-9.]+)");
    for (auto p = std::sregex_iterator(points.begin(), points.end(), pair); p != std::sregex_iterator(); ++p)
      out.back().push_back(std::stod((*p)[1]));
  }
  return out;
}

}  // namespace

TEST(StripChart, EachStripHasItsOwnScaleAndAPeakSurvivesDecimation) {
  const std::string svg = strip_chart_svg(two_strips(20000), 900, 170);
  const auto lines = ys(svg);
  ASSERT_EQ(lines.size(), 3u);
  // 20,000 samples on 810 pixels: at most two points per column.
  for (const auto& l : lines) EXPECT_LE(l.size(), 2u * 811);
  // The spike is the second strip's top: its smallest y is the strip's top edge (plus the 6% pad).
  const double top = *std::min_element(lines[2].begin(), lines[2].end());
  const double rest = lines[2].front();
  EXPECT_LT(top, rest - 100) << "the one-sample spike was lost";
  // Both position series share their strip's scale and fill it.
  const auto [lo, hi] = std::minmax_element(lines[0].begin(), lines[0].end());
  EXPECT_GT(*hi - *lo, 120);
}

TEST(StripChart, LabelsAreEscapedAndEveryTagCloses) {
  const std::string svg = strip_chart_svg(two_strips(100));
  EXPECT_NE(svg.find("A &lt;test&gt; &amp; chart"), std::string::npos);
  EXPECT_EQ(svg.find("<test>"), std::string::npos);
  EXPECT_EQ(svg.rfind("</svg>\n"), svg.size() - 7);
  EXPECT_NE(svg.find("Position (mm)"), std::string::npos);
  EXPECT_NE(svg.find("time (s)"), std::string::npos);
}

TEST(StripChart, CsvHasAHeaderAndOneRowPerSample) {
  StripChart c = two_strips(5);
  c.strips[1].series[0].label = "a, \"quoted\" label";
  const std::string csv = strip_chart_csv(c);
  const auto first = csv.substr(0, csv.find('\n'));
  EXPECT_EQ(first,
            "time_s,Position: command (mm),Position: encoder (mm),\"Error: a, \"\"quoted\"\" label (um)\"");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 6);
  EXPECT_NE(csv.find("\n0.004,"), std::string::npos);
}

TEST(StripChart, InconsistentDataIsRefused) {
  StripChart c = two_strips(5);
  c.strips[0].series[1].values.pop_back();
  EXPECT_THROW(strip_chart_svg(c), i20::UsageError);
  EXPECT_THROW(strip_chart_csv(c), i20::UsageError);
  EXPECT_THROW(strip_chart_svg(two_strips(1)), i20::UsageError);
}

// A value that is not a number is a gap: the line stops there and starts again after it (no
// line drawn across what was not measured), and the CSV leaves its field empty.
TEST(StripChart, AGapBreaksTheLineAndLeavesItsCsvFieldEmpty) {
  StripChart c = two_strips(100);
  auto& e = c.strips[1].series[0].values;
  for (std::size_t k = 40; k < 60; ++k) e[k] = std::nan("");
  const auto lines = ys(strip_chart_svg(c));
  ASSERT_EQ(lines.size(), 4u) << "the gapped series is not two lines";
  EXPECT_FALSE(lines[2].empty());
  EXPECT_FALSE(lines[3].empty());
  const std::string csv = strip_chart_csv(c);
  EXPECT_NE(csv.find("\n0.05,"), std::string::npos);
  const auto row =
      csv.substr(csv.find("\n0.05,") + 1, csv.find('\n', csv.find("\n0.05,") + 1) - csv.find("\n0.05,") - 1);
  EXPECT_EQ(row.back(), ',') << "a gap's field is not empty: " << row;
  EXPECT_EQ(csv.find("nan"), std::string::npos);
}

// Each strip reads off ticks of its own: a strip of +-0.4 gets several, not the one at 0 that
// a step rounded up to 0.5 would leave.
TEST(StripChart, AStripOfASmallRangeHasSeveralTicks) {
  StripChart c{"ticks", {}, {{"Shaft", "turns", {{"position", {}}}}}};
  for (std::size_t k = 0; k < 200; ++k) {
    c.time_s.push_back(static_cast<double>(k) * 1e-3);
    c.strips[0].series[0].values.push_back(0.41 * std::sin(static_cast<double>(k) * 0.05));
  }
  const std::string svg = strip_chart_svg(c);
  for (const char* tick : {">-0.4<", ">-0.2<", ">0<", ">0.2<", ">0.4<"})
    EXPECT_NE(svg.find(tick), std::string::npos) << "no tick " << tick;
}
