// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/strip_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <string_view>

#include "error/error.hpp"
#include "profile/svg_text.hpp"

namespace i20::profile {
namespace {

// Series colours: distinct on white and for the common colour blindnesses (Okabe-Ito).
constexpr const char* kColours[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9"};
constexpr int kLeft = 70, kRight = 20, kTop = 40, kGap = 34, kBottom = 40;

// Appends the parts in order (GCC 12 at -O3 misreads chains of `"literal" + std::string` as
// overlapping copies, -Wrestrict).
void put(std::string& out, std::initializer_list<std::string_view> parts) {
  for (auto part : parts) out.append(part);
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Ticks at 1, 2 or 5 times a power of ten spanning [lo, hi], about `about` of them.
std::vector<double> ticks(double lo, double hi, int about) {
  const double raw = (hi - lo) / about;
  const double power = std::pow(10, std::floor(std::log10(raw)));
  // The round step (1, 2 or 5 times a power of ten) nearest the wanted one: the next one up
  // can leave a strip with one tick (+-0.44 in steps of 0.5 has only 0).
  double step = power;
  for (double m : {2.0, 5.0, 10.0})
    if (std::abs(std::log(m * power / raw)) < std::abs(std::log(step / raw))) step = m * power;
  std::vector<double> out;
  for (double t = std::ceil(lo / step) * step; t <= hi + step * 1e-9; t += step)
    out.push_back(std::abs(t) < step * 1e-9 ? 0 : t);
  return out;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
};

Range range_of(const ChartStrip& strip) {
  Range r;
  for (const auto& s : strip.series)
    for (double v : s.values)
      if (std::isfinite(v)) {
        r.lo = std::min(r.lo, v);
        r.hi = std::max(r.hi, v);
      }
  if (!(r.lo <= r.hi)) r = {0, 1};
  if (r.hi - r.lo < 1e-12) {
    const double pad = std::max(std::abs(r.hi) * 0.1, 1e-9);
    r = {r.lo - pad, r.hi + pad};
  }
  const double pad = (r.hi - r.lo) * 0.06;
  return {r.lo - pad, r.hi + pad};
}

// A series as polylines, one per run of finite values (a value that is not a number is a gap:
// nothing was measured there), each with at most two points per pixel column (its least and
// greatest in the column, in the order they came): a 10,000-sample peak still shows at 900
// pixels.
std::vector<std::string> polylines(const std::vector<double>& t, const std::vector<double>& v, double t0,
                                   double t1, Range r, double x0, double w, double y0, double h) {
  std::vector<std::string> runs;
  const auto x_of = [&](double time) { return x0 + (time - t0) / (t1 - t0) * w; };
  const auto y_of = [&](double value) { return y0 + h - (value - r.lo) / (r.hi - r.lo) * h; };
  std::size_t k = 0;
  while (k < t.size()) {
    if (!std::isfinite(v[k])) {
      ++k;
      continue;
    }
    std::string& points = runs.emplace_back();
    while (k < t.size() && std::isfinite(v[k])) {
      const int column = static_cast<int>(x_of(t[k]));
      std::size_t lo = k, hi = k, end = k;
      while (end < t.size() && std::isfinite(v[end]) && static_cast<int>(x_of(t[end])) == column) {
        if (v[end] < v[lo]) lo = end;
        if (v[end] > v[hi]) hi = end;
        ++end;
      }
      for (std::size_t i : {std::min(lo, hi), std::max(lo, hi)}) {
        put(points, {svg_coordinate(x_of(t[i])), ",", svg_coordinate(y_of(v[i])), " "});
        if (lo == hi) break;
      }
      k = end;
    }
  }
  return runs;
}

void require_consistent(const StripChart& chart) {
  if (chart.time_s.size() < 2) throw UsageError("a chart needs at least two time samples");
  for (const auto& strip : chart.strips)
    for (const auto& s : strip.series)
      if (s.values.size() != chart.time_s.size()) {
        std::string why = "the chart's series '";
        put(why, {s.label, "' has ", std::to_string(s.values.size()), " values for ",
                  std::to_string(chart.time_s.size()), " times"});
        throw UsageError(why);
      }
}

}  // namespace

std::string strip_chart_svg(const StripChart& chart, int width, int strip_height) {
  require_consistent(chart);
  const int strips = static_cast<int>(chart.strips.size());
  const int height = kTop + strips * (strip_height + kGap) + kBottom - kGap;
  const double t0 = chart.time_s.front(), t1 = chart.time_s.back();
  const double plot_w = width - kLeft - kRight;
  const std::string left = std::to_string(kLeft), right_edge = svg_coordinate(kLeft + plot_w);
  std::string svg;
  put(svg, {"<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"", std::to_string(width), "\" height=\"",
            std::to_string(height), "\" font-family=\"sans-serif\" font-size=\"12\">\n",
            "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n", "<text x=\"", left,
            "\" y=\"22\" font-size=\"15\" font-weight=\"bold\">", xml_escaped(chart.title), "</text>\n"});
  const auto time_ticks = ticks(t0, t1, 10);
  std::size_t colour = 0;
  for (int i = 0; i < strips; ++i) {
    const auto& strip = chart.strips[i];
    const double y0 = kTop + i * (strip_height + kGap) + 16, h = strip_height - 16;
    const Range r = range_of(strip);
    put(svg, {"<g>\n<text x=\"", left, "\" y=\"", svg_coordinate(y0 - 5), "\" font-weight=\"bold\">",
              xml_escaped(strip.title), " (", xml_escaped(strip.unit), ")</text>\n<rect x=\"", left,
              "\" y=\"", svg_coordinate(y0), "\" width=\"", svg_coordinate(plot_w), "\" height=\"",
              svg_coordinate(h), "\" fill=\"none\" stroke=\"#888\"/>\n"});
    for (double tick : ticks(r.lo, r.hi, 4)) {
      const std::string y = svg_coordinate(y0 + h - (tick - r.lo) / (r.hi - r.lo) * h);
      put(svg, {"<line x1=\"", left, "\" x2=\"", right_edge, "\" y1=\"", y, "\" y2=\"", y,
                "\" stroke=\"#ddd\"/>\n<text x=\"", std::to_string(kLeft - 6), "\" y=\"",
                svg_coordinate(y0 + h - (tick - r.lo) / (r.hi - r.lo) * h + 4), "\" text-anchor=\"end\">",
                number(tick), "</text>\n"});
    }
    for (double tick : time_ticks) {
      const std::string x = svg_coordinate(kLeft + (tick - t0) / (t1 - t0) * plot_w);
      put(svg, {"<line x1=\"", x, "\" x2=\"", x, "\" y1=\"", svg_coordinate(y0), "\" y2=\"",
                svg_coordinate(y0 + h), "\" stroke=\"#eee\"/>\n"});
      if (i + 1 == strips)
        put(svg, {"<text x=\"", x, "\" y=\"", svg_coordinate(y0 + h + 16), "\" text-anchor=\"middle\">",
                  number(tick), "</text>\n"});
    }
    // The legend, right-aligned on the strip's title line, each label in its line's colour.
    double legend_x = kLeft + plot_w;
    for (std::size_t k = strip.series.size(); k-- > 0;) {
      legend_x -= 14 + 7.0 * static_cast<double>(strip.series[k].label.size());
      put(svg, {"<text x=\"", svg_coordinate(legend_x), "\" y=\"", svg_coordinate(y0 - 5), "\" fill=\"",
                kColours[(colour + k) % std::size(kColours)], "\">", xml_escaped(strip.series[k].label),
                "</text>\n"});
    }
    for (const auto& s : strip.series) {
      const char* stroke = kColours[colour++ % std::size(kColours)];
      for (const auto& points : polylines(chart.time_s, s.values, t0, t1, r, kLeft, plot_w, y0, h))
        put(svg, {"<polyline fill=\"none\" stroke=\"", stroke, "\" stroke-width=\"1.3\" points=\"", points,
                  "\"/>\n"});
    }
    put(svg, {"</g>\n"});
  }
  put(svg, {"<text x=\"", svg_coordinate(kLeft + plot_w / 2), "\" y=\"", std::to_string(height - 6),
            "\" text-anchor=\"middle\">time (s)</text>\n</svg>\n"});
  return svg;
}

std::string strip_chart_csv(const StripChart& chart) {
  require_consistent(chart);
  const auto field = [](const std::string& text) {  // RFC 4180: quoted, quotes doubled
    if (text.find_first_of(",\"\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) quoted.append(c == '"' ? 2 : 1, c);
    quoted += '"';
    return quoted;
  };
  std::string out = "time_s";
  for (const auto& strip : chart.strips)
    for (const auto& s : strip.series) {
      std::string name = strip.title;
      put(name, {": ", s.label, " (", strip.unit, ")"});
      put(out, {",", field(name)});
    }
  out += "\n";
  for (std::size_t k = 0; k < chart.time_s.size(); ++k) {
    out += number(chart.time_s[k]);
    for (const auto& strip : chart.strips)
      for (const auto& s : strip.series)  // a gap is an empty field
        put(out, {",", std::isfinite(s.values[k]) ? number(s.values[k]) : std::string()});
    out += "\n";
  }
  return out;
}

}  // namespace i20::profile
