// SPDX-License-Identifier: GPL-2.0-or-later
// The 48 Hall sequences LinuxCNC's bldc component accepts as its `pattern` parameter, built
// from the rule its table follows (see hall_table.cpp for the facts and their sources).
//
// A Hall code is bldc's table index: H1*4 + H2*2 + H3 (hall1 is the most significant bit).
// A sequence names the code the three sensors show in each of the six 60-degree sectors,
// sector k being centred on the electrical angle k*60 degrees in bldc's convention.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace i20::commission {

using HallCode = std::uint8_t;  // 0-7: H1*4 + H2*2 + H3

// Hall sensor n (1-3) as a bit of a HallCode.
constexpr HallCode hall_bit(int sensor) {
  return static_cast<HallCode>(4 >> (sensor - 1));
}

struct HallSequence {
  std::array<HallCode, 6> code_at_sector{};  // sector k is centred on k*60 electrical degrees
  bool operator==(const HallSequence&) const = default;
};

// Where the three sensors sit: three sensors 120 electrical degrees apart leave 000 and 111
// unused; 60 degrees apart (or 120 with one sensor's polarity reversed) leave another
// complementary pair unused.
enum class HallLayout { Deg120, Deg60 };

struct HallTableRow {
  HallSequence sequence;
  HallCode unused_low;  // the unused complementary pair: unused_low < unused_low ^ 7
  HallLayout layout;
  // bldc's `pattern` number (0-47), from bldc(9)'s documented table; every row has one
  // (tests/commission/hall_table_test.cpp checks the table against the rule it follows).
  std::optional<int> bldc_pattern;
};

// All 48 rows, in this library's own order (unused pair 000/111, 001/110, 010/101, 011/100;
// then the code at 0 degrees, ascending; then increasing before decreasing codes). The
// position in this table is NOT bldc's pattern number: that is HallTableRow::bldc_pattern.
std::span<const HallTableRow, 48> hall_table();

// The row whose sequence this is, or nullopt if it is not one of the 48.
std::optional<std::size_t> find_hall_row(const HallSequence& sequence);

// bldc's default pattern 25: 001->0, 101->60, 100->120, 110->180, 010->240, 011->300 degrees.
HallSequence bldc_pattern_25();

// How to feed bldc's hall1..hall3 from the sensors so that bldc's default pattern 25 applies:
// hall input n takes sensor source[n-1] (1-3), inverted (a `-not` pin) where invert[n-1].
// Every one of the 48 sequences has exactly one such rewiring (the cube's 48 symmetries act
// freely on the 48 sequences).
struct HallRewiring {
  std::array<int, 3> source{1, 2, 3};
  std::array<bool, 3> invert{false, false, false};
  bool is_identity() const;
  std::string describe() const;  // "hall1 <- sensor 2 inverted, hall2 <- sensor 1, ..."
};
HallRewiring rewiring_to_pattern_25(const HallSequence& sequence);
// The code bldc sees through `rewiring` when the sensors show `code`.
HallCode apply_rewiring(const HallRewiring& rewiring, HallCode code);

std::string hall_code_text(HallCode code);  // "101" (H1 H2 H3)

}  // namespace i20::commission
