// SPDX-License-Identifier: GPL-2.0-or-later
// bldc's Hall pattern table as rebuilt from the facts about it: 48 distinct rows, each a Gray
// 6-cycle with a complementary unused pair, 4 pairs x 6 codes at 0 degrees x 2 directions,
// and the default row equal to the mapping bldc documents for pattern 25.
#include "commission/hall_table.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <map>
#include <set>

using namespace i20::commission;

namespace {

bool one_bit_apart(HallCode a, HallCode b) {
  return std::popcount(static_cast<unsigned>(a ^ b)) == 1;
}

TEST(HallTable, HasFortyEightDistinctRows) {
  std::set<std::array<HallCode, 6>> distinct;
  for (const HallTableRow& row : hall_table()) distinct.insert(row.sequence.code_at_sector);
  EXPECT_EQ(distinct.size(), 48u);
}

TEST(HallTable, EveryRowIsAGrayCycleWithAComplementaryUnusedPair) {
  for (const HallTableRow& row : hall_table()) {
    const auto& codes = row.sequence.code_at_sector;
    std::set<HallCode> used(codes.begin(), codes.end());
    EXPECT_EQ(used.size(), 6u);
    for (std::size_t k = 0; k < 6; ++k) EXPECT_TRUE(one_bit_apart(codes[k], codes[(k + 1) % 6]));
    EXPECT_FALSE(used.count(row.unused_low));
    EXPECT_FALSE(used.count(row.unused_low ^ 7));
    EXPECT_EQ(row.layout == HallLayout::Deg120, row.unused_low == 0);
  }
}

TEST(HallTable, IsFourPairsTimesSixStartsTimesTwoDirections) {
  std::set<std::tuple<HallCode, HallCode, HallCode>> combinations;  // pair, code at 0, code at 60
  for (const HallTableRow& row : hall_table()) {
    combinations.insert({row.unused_low, row.sequence.code_at_sector[0], row.sequence.code_at_sector[1]});
  }
  EXPECT_EQ(combinations.size(), 48u);
  for (HallCode pair = 0; pair < 4; ++pair) {
    std::set<HallCode> starts;
    for (const HallTableRow& row : hall_table()) {
      if (row.unused_low == pair) starts.insert(row.sequence.code_at_sector[0]);
    }
    EXPECT_EQ(starts.size(), 6u) << "pair " << int(pair);
  }
}

TEST(HallTable, PatternTwentyFiveIsBldcsDocumentedDefault) {
  // 001->0, 101->60, 100->120, 110->180, 010->240, 011->300 degrees.
  const HallSequence stated{{0b001, 0b101, 0b100, 0b110, 0b010, 0b011}};
  const auto row = find_hall_row(stated);
  ASSERT_TRUE(row);
  EXPECT_EQ(hall_table()[*row].bldc_pattern, 25);
  EXPECT_EQ(hall_table()[*row].layout, HallLayout::Deg120);
  EXPECT_EQ(bldc_pattern_25(), stated);
}

// bldc(9)'s documented numbering covers exactly the 48 rows the rule builds, each number once,
// and agrees with what its description says of its common patterns: 17 is a 120-degree
// layout, 0 and 26 are each other's reverse.
TEST(HallTable, EveryRowHasOneBldcNumberAndEachNumberOneRow) {
  std::set<int> numbers;
  std::map<int, HallSequence> by_number;
  for (const HallTableRow& row : hall_table()) {
    ASSERT_TRUE(row.bldc_pattern) << "a row the rule builds is missing from bldc's table";
    EXPECT_GE(*row.bldc_pattern, 0);
    EXPECT_LE(*row.bldc_pattern, 47);
    numbers.insert(*row.bldc_pattern);
    by_number[*row.bldc_pattern] = row.sequence;
  }
  EXPECT_EQ(numbers.size(), 48u);
  EXPECT_EQ(hall_table()[*find_hall_row(by_number[17])].layout, HallLayout::Deg120);
  HallSequence reversed{};
  for (std::size_t k = 0; k < 6; ++k) reversed.code_at_sector[k] = by_number[0].code_at_sector[(6 - k) % 6];
  // "26, its reverse": the same codes visited the other way round (from another start).
  bool same_cycle = false;
  for (std::size_t shift = 0; shift < 6 && !same_cycle; ++shift) {
    HallSequence shifted{};
    for (std::size_t k = 0; k < 6; ++k) shifted.code_at_sector[k] = reversed.code_at_sector[(k + shift) % 6];
    same_cycle = shifted == by_number[26];
  }
  EXPECT_TRUE(same_cycle);
}

TEST(HallTable, EveryRowReachesPatternTwentyFiveByOneRewiring) {
  const HallSequence target = bldc_pattern_25();
  std::set<std::string> rewirings;
  for (const HallTableRow& row : hall_table()) {
    const HallRewiring rewiring = rewiring_to_pattern_25(row.sequence);
    HallSequence seen{};
    for (std::size_t k = 0; k < 6; ++k)
      seen.code_at_sector[k] = apply_rewiring(rewiring, row.sequence.code_at_sector[k]);
    EXPECT_EQ(seen, target);
    rewirings.insert(rewiring.describe());
    EXPECT_EQ(rewiring.is_identity(), row.bldc_pattern == 25);
  }
  EXPECT_EQ(rewirings.size(), 48u) << "each row needs its own rewiring";
}

TEST(HallTable, FindsItsOwnRowsAndNothingElse) {
  for (std::size_t i = 0; i < hall_table().size(); ++i) EXPECT_EQ(find_hall_row(hall_table()[i].sequence), i);
  EXPECT_FALSE(find_hall_row(HallSequence{{1, 5, 4, 6, 2, 2}}));
  EXPECT_EQ(hall_code_text(0b101), "101");
}

}  // namespace
