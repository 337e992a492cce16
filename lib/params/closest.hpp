// SPDX-License-Identifier: GPL-2.0-or-later
// "Did you mean ...?": ranking known names by closeness to what a user typed. Shared by
// the parameter database and the fault table, so both suggest the same way.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace i20::params {

// Levenshtein distance.
std::size_t edit_distance(std::string_view a, std::string_view b);

struct Candidate {
  std::string suggestion;              // what to offer ("NVBRAKEONV", "bus-under-voltage")
  std::vector<std::string> spellings;  // every name it is known by
};

// Up to `max` suggestions, closest first, compared case-insensitively: a spelling within
// an edit distance of max(2, length/3), or one containing what was typed (3+ letters).
std::vector<std::string> closest(std::string_view typed, const std::vector<Candidate>& candidates,
                                 std::size_t max);

}  // namespace i20::params
