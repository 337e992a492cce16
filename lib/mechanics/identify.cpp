// SPDX-License-Identifier: GPL-2.0-or-later
#include "mechanics/identify.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace i20::mechanics {
namespace {

constexpr std::size_t kTerms = 4;  // inertia, viscous, Coulomb, bias
using Row = std::array<double, kTerms>;
using Square = std::array<Row, kTerms>;

// Fewer windows than this cannot give four values with an honest spread.
constexpr std::size_t kLeastWindows = 12;
// Each direction needs a few windows of its own, or the Coulomb term and the bias are one.
constexpr std::size_t kLeastWindowsPerDirection = 3;

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

struct Window {
  Row x{};
  double y = 0;
  double from_s = 0, to_s = 0;  // its edges' times
};

// Inverts a symmetric positive-definite matrix (Gauss-Jordan, partial pivoting); throws
// when a column is (numerically) a combination of the others.
Square inverse(Square a) {
  Square inv{};
  for (std::size_t i = 0; i < kTerms; ++i) inv[i][i] = 1;
  for (std::size_t col = 0; col < kTerms; ++col) {
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < kTerms; ++r)
      if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
    if (std::abs(a[pivot][col]) < 1e-9)
      throw IdentifyError(
          "the move cannot tell the terms apart (its speeds and accelerations are too alike): move "
          "further or at more than one speed");
    std::swap(a[col], a[pivot]);
    std::swap(inv[col], inv[pivot]);
    const double p = a[col][col];
    for (std::size_t c = 0; c < kTerms; ++c) {
      a[col][c] /= p;
      inv[col][c] /= p;
    }
    for (std::size_t r = 0; r < kTerms; ++r) {
      if (r == col) continue;
      const double f = a[r][col];
      for (std::size_t c = 0; c < kTerms; ++c) {
        a[r][c] -= f * a[col][c];
        inv[r][c] -= f * inv[col][c];
      }
    }
  }
  return inv;
}

std::vector<Window> windows_of(std::span<const MotionSample> s, const IdentifyOptions& o) {
  if (s.size() < 3) throw IdentifyError("too few samples to identify anything");
  const double period = (s.back().time_s - s.front().time_s) / static_cast<double>(s.size() - 1);
  if (!(period > 0)) throw IdentifyError("the samples' times do not increase");
  const auto samples_in = [&](double seconds) {
    return std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(seconds / period)));
  };
  const std::size_t span = samples_in(o.speed_span_s), length = samples_in(o.window_s);
  const auto speed = [&](std::size_t k) {
    return (s[k + span].position_rad - s[k - span].position_rad) / (s[k + span].time_s - s[k - span].time_s);
  };
  std::vector<Window> out;
  for (std::size_t a = span; a + length + span < s.size(); a += length) {
    const std::size_t b = a + length;
    const double direction = speed(a) > 0 ? 1.0 : -1.0;
    bool steady = true;  // one direction throughout, never creeping
    for (std::size_t k = a; k <= b && steady; ++k) steady = direction * speed(k) >= o.least_speed_rad_s;
    if (!steady) continue;
    Window w;
    for (std::size_t k = a; k < b; ++k) w.y += s[k].torque_nm * (s[k + 1].time_s - s[k].time_s);
    const double duration = s[b].time_s - s[a].time_s;
    w.x = {speed(b) - speed(a), s[b].position_rad - s[a].position_rad, direction * duration, duration};
    w.from_s = s[a].time_s;
    w.to_s = s[b].time_s;
    out.push_back(w);
  }
  return out;
}

void require_both_directions(const std::vector<Window>& windows) {
  std::size_t forward = 0, backward = 0;
  for (const auto& w : windows) (w.x[2] > 0 ? forward : backward)++;
  if (forward < kLeastWindowsPerDirection || backward < kLeastWindowsPerDirection)
    throw IdentifyError("the move must run both ways to tell friction from a bias (" +
                        std::to_string(forward) + " windows forward, " + std::to_string(backward) +
                        " backward, at least " + std::to_string(kLeastWindowsPerDirection) + " each)");
}

}  // namespace

Mechanics identify(std::span<const MotionSample> samples, const IdentifyOptions& options) {
  const auto windows = windows_of(samples, options);
  if (windows.size() < kLeastWindows)
    throw IdentifyError("only " + std::to_string(windows.size()) + " windows of steady motion (at least " +
                        std::to_string(kLeastWindows) + "): move longer, or faster than " +
                        number(options.least_speed_rad_s) + " rad/s");
  require_both_directions(windows);
  // Each column scaled to unit RMS first: inertia's column is ~1e4 times smaller than the bias's.
  Row scale{};
  for (const auto& w : windows)
    for (std::size_t i = 0; i < kTerms; ++i) scale[i] += w.x[i] * w.x[i];
  for (auto& v : scale) v = v > 0 ? std::sqrt(v / static_cast<double>(windows.size())) : 1;
  Square normal{};
  Row moment{};
  for (const auto& w : windows)
    for (std::size_t i = 0; i < kTerms; ++i) {
      moment[i] += w.x[i] / scale[i] * w.y;
      for (std::size_t j = 0; j < kTerms; ++j) normal[i][j] += w.x[i] / scale[i] * w.x[j] / scale[j];
    }
  const Square covariance = inverse(normal);  // of the scaled values, per unit residual variance
  Row fit{};
  for (std::size_t i = 0; i < kTerms; ++i)
    for (std::size_t j = 0; j < kTerms; ++j) fit[i] += covariance[i][j] * moment[j];
  double squares = 0;
  for (const auto& w : windows) {
    double predicted = 0;
    for (std::size_t i = 0; i < kTerms; ++i) predicted += fit[i] / scale[i] * w.x[i];
    squares += (w.y - predicted) * (w.y - predicted);
  }
  const double variance = squares / static_cast<double>(windows.size() - kTerms);
  const auto estimate = [&](std::size_t i) {
    return Estimate{fit[i] / scale[i], std::sqrt(variance * covariance[i][i]) / scale[i]};
  };
  Mechanics m;
  m.inertia_kgm2 = estimate(0);
  m.viscous_nm_per_rad_s = estimate(1);
  m.coulomb_nm = estimate(2);
  m.bias_nm = estimate(3);
  m.windows = windows.size();
  m.residual_nm_s = std::sqrt(squares / static_cast<double>(windows.size()));
  return m;
}

std::vector<FitWindow> fit_windows(std::span<const MotionSample> samples, const Mechanics& m,
                                   const IdentifyOptions& options) {
  const Row fitted{m.inertia_kgm2.value, m.viscous_nm_per_rad_s.value, m.coulomb_nm.value, m.bias_nm.value};
  std::vector<FitWindow> out;
  for (const auto& w : windows_of(samples, options)) {
    const double duration = w.to_s - w.from_s;
    double predicted = 0;
    for (std::size_t i = 0; i < kTerms; ++i) predicted += fitted[i] * w.x[i];
    out.push_back({w.from_s, w.to_s, w.y / duration, predicted / duration});
  }
  return out;
}

}  // namespace i20::mechanics
