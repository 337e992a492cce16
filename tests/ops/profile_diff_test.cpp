// SPDX-License-Identifier: GPL-2.0-or-later
// `profile diff` answers as diff(1) does: same, differs, or trouble when it could not compare
// (a card not read, a value that is not a fact on it), and interrupted when stopped.
#include "ops/profile_diff.hpp"

#include <gtest/gtest.h>

#include <utility>

using i20::ops::Comparison;
using i20::ops::ProfileDiff;
using i20::profile::DiffRow;

namespace {

ProfileDiff of(std::vector<DiffRow> rows) {
  ProfileDiff d;
  d.rows = std::move(rows);
  return d;
}

DiffRow row(const std::string& cell, std::int64_t profile, std::optional<std::int64_t> card) {
  DiffRow r;
  r.cell = cell;
  r.profile_raw = profile;
  r.card_raw = card;
  r.equal = card && *card == profile;
  return r;
}

}  // namespace

TEST(ProfileDiff, EveryValueHeldIsSame) {
  const ProfileDiff d = of({row("NVKQP", 50, 50), row("NVKDP", 60, 60)});
  EXPECT_EQ(d.differ(), 0);
  EXPECT_EQ(d.unknown(), 0);
  EXPECT_EQ(d.comparison(), Comparison::Same);
  EXPECT_EQ(ProfileDiff{}.comparison(), Comparison::Same) << "a profile of no cells: nothing differs";
}

TEST(ProfileDiff, AValueTheCardHoldsOtherwiseDiffers) {
  const ProfileDiff d = of({row("NVKQP", 50, 50), row("NVKDP", 60, 70)});
  EXPECT_EQ(d.differ(), 1);
  EXPECT_EQ(d.comparison(), Comparison::Differs);
}

TEST(ProfileDiff, AValueThatIsNoFactOnTheCardIsTroubleNotSame) {
  ProfileDiff d = of({row("NVKQP", 50, 50), row("KQP", 50, std::nullopt)});
  EXPECT_EQ(d.unknown(), 1);
  EXPECT_EQ(d.differ(), 0) << "an unknown value is not counted as differing";
  EXPECT_EQ(d.comparison(), Comparison::Trouble);
  d.rows.push_back(row("NVKDP", 60, 70));
  EXPECT_EQ(d.comparison(), Comparison::Trouble) << "trouble outranks a difference";
}

TEST(ProfileDiff, ACardNotReadIsTroubleAndAStopIsInterrupted) {
  ProfileDiff d;
  d.error = "no answer from the card";
  EXPECT_EQ(d.comparison(), Comparison::Trouble);
  d.interrupted = true;
  EXPECT_EQ(d.comparison(), Comparison::Interrupted);
}
