// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/text_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "profile/plot_scale.hpp"

namespace i20::profile {
namespace {

constexpr std::array<const char*, 9> kEighths{" ", "▁", "▂", "▃", "▄", "▅", "▆", "▇", "█"};

struct Glyphs {
  bool unicode;
  std::string cell(double fill) const {
    if (fill >= 1.0) return unicode ? kEighths[8] : "#";
    if (fill <= 0.0) return " ";
    if (unicode) return kEighths[std::clamp(static_cast<int>(fill * 8.0), 0, 8)];
    return fill >= 0.5 ? ":" : ".";
  }
  std::string command() const { return unicode ? "┈" : "-"; }
  std::string tick() const { return unicode ? "┤" : "|"; }
  std::string bar() const { return unicode ? "│" : "|"; }
  std::string corner() const { return unicode ? "└" : "+"; }
  std::string rule() const { return unicode ? "─" : "-"; }
};

// The highest current in each column's time slice, so overshoot shows even when squeezed.
std::vector<double> columns(const StepResponse& r, int width) {
  std::vector<double> out(static_cast<std::size_t>(width), 0.0);
  if (r.samples.empty()) return out;
  const double t_end = std::max(r.samples.back().t_s, 1e-12);
  std::vector<bool> filled(out.size(), false);
  for (const auto& s : r.samples) {
    const auto c = std::min<std::size_t>(out.size() - 1, static_cast<std::size_t>(s.t_s / t_end * width));
    out[c] = filled[c] ? std::max(out[c], s.current_a) : s.current_a;
    filled[c] = true;
  }
  for (std::size_t c = 1; c < out.size(); ++c)
    if (!filled[c]) out[c] = out[c - 1];  // fewer samples than columns: hold the last value
  return out;
}

std::string label(double amps) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%7.2f A ", amps);
  return buf;
}

}  // namespace

std::string step_response_text(const StepResponse& response, const TextPlotOptions& options) {
  const int width = std::max(options.width, 8);
  const int height = std::max(options.height, 2);
  const Glyphs g{options.unicode};
  const double top = std::max(current_axis_top(response), 1e-9);
  const auto values = columns(response, width);
  const double row_span = top / height;
  const int command_row =
      std::clamp(height - 1 - static_cast<int>(response.step_a / row_span), 0, height - 1);

  std::string out;
  for (int row = 0; row < height; ++row) {
    const double lo = (height - 1 - row) * row_span;
    const bool is_command = row == command_row;
    out += is_command ? label(response.step_a) : row == 0 ? label(top) : std::string(10, ' ');
    out += row == 0 || is_command ? g.tick() : g.bar();
    for (const double v : values) {
      const std::string c = g.cell((v - lo) / row_span);
      out += is_command && c == " " ? g.command() : c;
    }
    out += "\n";
  }
  out += label(0) + g.corner();
  for (int c = 0; c < width; ++c) out += g.rule();
  out += "\n";
  char end[32];
  std::snprintf(end, sizeof end, "%.3f ms",
                response.samples.empty() ? 0.0 : response.samples.back().t_s * 1e3);
  const std::string axis = std::string(11, ' ') + "0";
  out += axis +
         std::string(
             static_cast<std::size_t>(std::max<int>(1, width - static_cast<int>(std::string(end).size()))),
             ' ') +
         end + "\n";
  out += metrics_summary(response) + "\n";
  return out;
}

}  // namespace i20::profile
