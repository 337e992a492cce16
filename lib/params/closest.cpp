// SPDX-License-Identifier: GPL-2.0-or-later
#include "params/closest.hpp"

#include <algorithm>
#include <cctype>

#include "params/text.hpp"

namespace i20::params {
namespace {}  // namespace

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::vector<std::string> closest(std::string_view typed, const std::vector<Candidate>& candidates,
                                 std::size_t max) {
  const auto wanted = lower(typed);
  const std::size_t tolerance = std::max<std::size_t>(2, wanted.size() / 3);
  std::vector<std::pair<std::size_t, std::string>> scored;
  for (const auto& c : candidates) {
    std::size_t best = tolerance + 1;
    for (const auto& spelling : c.spellings) {
      const auto s = lower(spelling);
      best = std::min(best, edit_distance(wanted, s));
      if (wanted.size() >= 3 && s.find(wanted) != std::string::npos) best = std::min(best, tolerance);
    }
    if (best <= tolerance) scored.emplace_back(best, c.suggestion);
  }
  std::ranges::sort(scored);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < scored.size() && i < max; ++i) out.push_back(scored[i].second);
  return out;
}

}  // namespace i20::params
