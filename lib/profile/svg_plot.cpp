// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/svg_plot.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "profile/plot_scale.hpp"
#include "profile/svg_text.hpp"

namespace i20::profile {
namespace {

constexpr double kLeft = 70, kRight = 24, kTop = 58, kBottom = 56;
constexpr std::size_t kMaxPoints = 3000;

// Maps time (ms) and current (A) to pixels.
struct Frame {
  double width, height, t_max_ms, i_max;
  double x(double t_ms) const { return kLeft + t_ms / t_max_ms * (width - kLeft - kRight); }
  double y(double amps) const { return height - kBottom - amps / i_max * (height - kTop - kBottom); }
  double x0() const { return kLeft; }
  double x1() const { return width - kRight; }
  double y0() const { return height - kBottom; }
  double y1() const { return kTop; }
};

void line(std::ostringstream& out, double x1, double y1, double x2, double y2, const std::string& style) {
  out << "<line x1=\"" << svg_coordinate(x1) << "\" y1=\"" << svg_coordinate(y1) << "\" x2=\""
      << svg_coordinate(x2) << "\" y2=\"" << svg_coordinate(y2) << "\" " << style << "/>\n";
}

void text(std::ostringstream& out, double x, double y, const std::string& body,
          const std::string& attrs = "") {
  out << "<text x=\"" << svg_coordinate(x) << "\" y=\"" << svg_coordinate(y) << "\""
      << (attrs.empty() ? "" : " " + attrs) << ">" << xml_escaped(body) << "</text>\n";
}

void grid_and_axes(std::ostringstream& out, const Frame& f) {
  out << "<g id=\"grid\">\n";
  for (const double t : nice_ticks(f.t_max_ms, 8)) {
    line(out, f.x(t), f.y0(), f.x(t), f.y1(), "stroke=\"#e0e0e0\"");
    text(out, f.x(t), f.y0() + 16, tick_label(t), "text-anchor=\"middle\"");
  }
  for (const double a : nice_ticks(f.i_max, 6)) {
    line(out, f.x0(), f.y(a), f.x1(), f.y(a), "stroke=\"#e0e0e0\"");
    text(out, f.x0() - 6, f.y(a) + 4, tick_label(a), "text-anchor=\"end\"");
  }
  out << "</g>\n<g id=\"axes\">\n";
  line(out, f.x0(), f.y0(), f.x1(), f.y0(), "stroke=\"black\"");
  line(out, f.x0(), f.y0(), f.x0(), f.y1(), "stroke=\"black\"");
  text(out, (f.x0() + f.x1()) / 2, f.height - 14, "time (ms)", "text-anchor=\"middle\"");
  out << "<text x=\"16\" y=\"" << svg_coordinate((f.y0() + f.y1()) / 2)
      << "\" text-anchor=\"middle\" transform=\"rotate(-90 16 " << svg_coordinate((f.y0() + f.y1()) / 2)
      << ")\">current (A)</text>\n";
  out << "</g>\n";
}

void traces(std::ostringstream& out, const Frame& f, const StepResponse& r) {
  const double end_ms = f.t_max_ms;
  out << "<polyline id=\"command\" fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" "
         "stroke-dasharray=\"6 4\" points=\""
      << svg_coordinate(f.x(0)) << "," << svg_coordinate(f.y(0)) << " " << svg_coordinate(f.x(0)) << ","
      << svg_coordinate(f.y(r.step_a)) << " " << svg_coordinate(f.x(end_ms)) << ","
      << svg_coordinate(f.y(r.step_a)) << "\"/>\n";
  const std::size_t stride = std::max<std::size_t>(1, r.samples.size() / kMaxPoints);
  out << "<polyline id=\"response\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"2\" points=\"";
  for (std::size_t k = 0; k < r.samples.size(); k += stride) {
    const auto& s = r.samples[k];
    out << (k ? " " : "") << svg_coordinate(f.x(s.t_s * 1e3)) << ","
        << svg_coordinate(f.y(std::clamp(s.current_a, 0.0, f.i_max)));
  }
  out << "\"/>\n";
}

void annotations(std::ostringstream& out, const Frame& f, const StepResponse& r) {
  const StepMetrics& m = r.metrics;
  out << "<g id=\"annotations\" font-size=\"11\">\n";
  if (m.rise_time_s && m.rise_start_s) {
    const double t10 = *m.rise_start_s;
    const double t90 = t10 + *m.rise_time_s;
    for (const double t : {t10, t90})
      line(out, f.x(t * 1e3), f.y0(), f.x(t * 1e3), f.y(r.step_a),
           "stroke=\"#2ca02c\" stroke-dasharray=\"2 3\"");
    char buf[64];
    std::snprintf(buf, sizeof buf, "rise %.3f ms", *m.rise_time_s * 1e3);
    text(out, f.x(t90 * 1e3) + 4, f.y(0.5 * r.step_a), buf, "fill=\"#2ca02c\"");
  }
  if (m.overshoot_pct > 0.05) {
    const double peak = r.step_a * (1 + m.overshoot_pct / 100);
    line(out, f.x0(), f.y(peak), f.x1(), f.y(peak), "stroke=\"#9467bd\" stroke-dasharray=\"4 3\"");
    char buf[64];
    std::snprintf(buf, sizeof buf, "overshoot %.1f%%", m.overshoot_pct);
    text(out, f.x1() - 4, f.y(peak) - 4, buf, "text-anchor=\"end\" fill=\"#9467bd\"");
  }
  out << "</g>\n";
}

void legend(std::ostringstream& out, const Frame& f) {
  const double x = f.x1() - 150, y = f.y0() - 40;
  out << "<g id=\"legend\">\n";
  line(out, x, y, x + 24, y, "stroke=\"#1f77b4\" stroke-width=\"1.5\" stroke-dasharray=\"6 4\"");
  text(out, x + 30, y + 4, "command");
  line(out, x, y + 18, x + 24, y + 18, "stroke=\"#d62728\" stroke-width=\"2\"");
  text(out, x + 30, y + 22, "current");
  out << "</g>\n";
}

}  // namespace

std::string step_response_svg(const StepResponse& response, const SvgOptions& options) {
  const double t_end = response.samples.empty() ? 1e-3 : response.samples.back().t_s;
  const Frame f{static_cast<double>(options.width), static_cast<double>(options.height),
                std::max(t_end * 1e3, 1e-6), std::max(current_axis_top(response), 1e-9)};
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << options.width << "\" height=\""
      << options.height << "\" viewBox=\"0 0 " << options.width << " " << options.height
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  text(out, f.width / 2, 22, options.title, "text-anchor=\"middle\" font-size=\"15\"");
  text(out, f.width / 2, 42, metrics_summary(response), "text-anchor=\"middle\" fill=\"#444\"");
  grid_and_axes(out, f);
  traces(out, f, response);
  annotations(out, f, response);
  legend(out, f);
  out << "</svg>\n";
  return out.str();
}

}  // namespace i20::profile
