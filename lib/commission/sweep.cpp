// SPDX-License-Identifier: GPL-2.0-or-later
#include "commission/sweep.hpp"

#include <cmath>

namespace i20::commission {

namespace {

// Movements smaller than this are a hold, not a sweep (turns per sample).
constexpr double kStillTurns = 1e-9;

std::vector<double> unwrapped_command(std::span<const Sample> samples) {
  std::vector<double> command;
  command.reserve(samples.size());
  double shift = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double raw = samples[i].commanded_electrical_turns;
    if (i > 0) {
      const double step = raw + shift - command.back();
      shift -= std::round(step);  // a jump of more than half a turn is a wrap
    }
    command.push_back(raw + shift);
  }
  return command;
}

int direction_of(double step) {
  if (step > kStillTurns) return 1;
  if (step < -kStillTurns) return -1;
  return 0;
}

}  // namespace

double Sweep::steady_travel(int direction) const {
  double travel = 0;
  for (const SweepRun& run : runs) {
    if (run.direction == direction) travel += std::abs(command[run.end - 1] - run.steady_start_turns);
  }
  return travel;
}

std::size_t Sweep::steady_count(int direction) const {
  std::size_t n = 0;
  for (const SweepRun& run : runs) {
    if (run.direction == direction) n += run.end - run.steady_begin;
  }
  return n;
}

Sweep read_sweep(std::span<const Sample> samples, double settle_turns) {
  Sweep sweep;
  sweep.command = unwrapped_command(samples);
  const auto& command = sweep.command;
  std::size_t i = 1;
  while (i < command.size()) {
    const int direction = direction_of(command[i] - command[i - 1]);
    if (direction == 0) {
      ++i;
      continue;
    }
    const double start = command[i - 1];
    std::size_t end = i;
    while (end < command.size() && direction_of(command[end] - command[end - 1]) == direction) ++end;
    std::size_t steady = i;
    while (steady < end && std::abs(command[steady] - start) < settle_turns) ++steady;
    if (steady < end) sweep.runs.push_back({direction, steady, end, command[steady]});
    i = end;
  }
  return sweep;
}

}  // namespace i20::commission
