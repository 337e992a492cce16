// SPDX-License-Identifier: GPL-2.0-or-later
// `i20 profile diff`: a profile against what one card holds, and the answer it gives, as
// diff(1) does (ops::Comparison). The rule is lib/ops's; the app only renders it.
#pragma once

#include <string>
#include <vector>

#include "ops/core/outcome.hpp"
#include "profile/diff.hpp"

namespace i20::ops {

// One target's comparison: the rows when the card was read, or why it was not.
struct ProfileDiff {
  std::vector<profile::DiffRow> rows;  // the profile's cells against the card's values
  std::string error;                   // why the card was not read; empty when it was
  bool interrupted = false;            // a stop request (Ctrl-C, ...) ended the read

  // Values the card holds as facts and that differ from the profile's.
  long differ() const;
  // Values that are no fact on the card (an address not confirmed for its firmware).
  long unknown() const;
  // Interrupted when stopped; Trouble when the card was not read or a value is not a fact
  // there (it was not compared, so "same" cannot be claimed); Differs; else Same.
  Comparison comparison() const;
};

}  // namespace i20::ops
