// SPDX-License-Identifier: GPL-2.0-or-later
// bldc's Hall pattern table, rebuilt from facts about it rather than copied.
//
// Facts used (LinuxCNC src/hal/components/bldc.comp: the P[] table, its man-page table and
// the trapezoidal mode; read as a snapshot, not copied):
//  - Each of the 48 rows maps a Hall code H1H2H3 (index H1*4+H2*2+H3) to an excitation code.
//  - An excitation code stands for a sector whose centre is the rotor angle: B-C 0 degrees,
//    B-A 60, C-A 120, C-B 180, A-B 240, A-C 300 (excitation 040/020/010 = A+/B+/C+, 004/002/001
//    = A-/B-/C-). So a row is equivalently "which Hall code shows in each 60-degree sector".
//  - Every row is a 6-step Gray cycle (one sensor changes per sector) whose two unused codes
//    are complementary (000/111, 001/110, 010/101 or 011/100); the 48 rows are all distinct
//    and are exactly 4 excluded pairs x 6 codes at 0 degrees x 2 directions.
//  - Row 25, the default: 001->0, 101->60, 100->120, 110->180, 010->240, 011->300 degrees.
// The cube {0,1}^3 without two opposite corners is a single 6-cycle, so each excluded pair
// gives exactly one cycle; 6 starting codes x 2 directions make its 12 rows. That fixes the
// set of 48 rows. Which number bldc gives each row comes from bldc(9)'s documented table
// (the `pattern` parameter's table in bldc.comp's description: for each pattern number, the
// Hall code H1H2H3 in each excitation's sector), restated below by sector centre; the tests
// check that it is exactly the set built from the rule, with 25 as stated.
#include "commission/hall_table.hpp"

#include <algorithm>
#include <bit>
#include <vector>

namespace i20::commission {

namespace {

// bldc(9)'s pattern table by number: the Hall code shown in the sectors centred on 0, 60,
// 120, 180, 240 and 300 electrical degrees (the documented columns B-C, B-A, C-A, C-B, A-B,
// A-C).
constexpr std::array<std::array<HallCode, 6>, 48> kBldcPatterns{{
    {{0b100, 0b000, 0b001, 0b011, 0b111, 0b110}},  // 0
    {{0b101, 0b001, 0b000, 0b010, 0b110, 0b111}},  // 1
    {{0b100, 0b000, 0b010, 0b011, 0b111, 0b101}},  // 2
    {{0b101, 0b001, 0b011, 0b010, 0b110, 0b100}},  // 3
    {{0b110, 0b010, 0b011, 0b001, 0b101, 0b100}},  // 4
    {{0b111, 0b011, 0b010, 0b000, 0b100, 0b101}},  // 5
    {{0b110, 0b010, 0b000, 0b001, 0b101, 0b111}},  // 6
    {{0b111, 0b011, 0b001, 0b000, 0b100, 0b110}},  // 7
    {{0b010, 0b000, 0b001, 0b101, 0b111, 0b110}},  // 8
    {{0b011, 0b001, 0b000, 0b100, 0b110, 0b111}},  // 9
    {{0b001, 0b000, 0b010, 0b110, 0b111, 0b101}},  // 10
    {{0b000, 0b001, 0b011, 0b111, 0b110, 0b100}},  // 11
    {{0b000, 0b010, 0b011, 0b111, 0b101, 0b100}},  // 12
    {{0b001, 0b011, 0b010, 0b110, 0b100, 0b101}},  // 13
    {{0b011, 0b010, 0b000, 0b100, 0b101, 0b111}},  // 14
    {{0b010, 0b011, 0b001, 0b101, 0b100, 0b110}},  // 15
    {{0b010, 0b000, 0b100, 0b101, 0b111, 0b011}},  // 16
    {{0b011, 0b001, 0b101, 0b100, 0b110, 0b010}},  // 17
    {{0b001, 0b000, 0b100, 0b110, 0b111, 0b011}},  // 18
    {{0b000, 0b001, 0b101, 0b111, 0b110, 0b010}},  // 19
    {{0b000, 0b010, 0b110, 0b111, 0b101, 0b001}},  // 20
    {{0b001, 0b011, 0b111, 0b110, 0b100, 0b000}},  // 21
    {{0b011, 0b010, 0b110, 0b100, 0b101, 0b001}},  // 22
    {{0b010, 0b011, 0b111, 0b101, 0b100, 0b000}},  // 23
    {{0b000, 0b100, 0b101, 0b111, 0b011, 0b010}},  // 24
    {{0b001, 0b101, 0b100, 0b110, 0b010, 0b011}},  // 25
    {{0b000, 0b100, 0b110, 0b111, 0b011, 0b001}},  // 26
    {{0b001, 0b101, 0b111, 0b110, 0b010, 0b000}},  // 27
    {{0b010, 0b110, 0b111, 0b101, 0b001, 0b000}},  // 28
    {{0b011, 0b111, 0b110, 0b100, 0b000, 0b001}},  // 29
    {{0b010, 0b110, 0b100, 0b101, 0b001, 0b011}},  // 30
    {{0b011, 0b111, 0b101, 0b100, 0b000, 0b010}},  // 31
    {{0b110, 0b100, 0b101, 0b001, 0b011, 0b010}},  // 32
    {{0b111, 0b101, 0b100, 0b000, 0b010, 0b011}},  // 33
    {{0b101, 0b100, 0b110, 0b010, 0b011, 0b001}},  // 34
    {{0b100, 0b101, 0b111, 0b011, 0b010, 0b000}},  // 35
    {{0b100, 0b110, 0b111, 0b011, 0b001, 0b000}},  // 36
    {{0b101, 0b111, 0b110, 0b010, 0b000, 0b001}},  // 37
    {{0b111, 0b110, 0b100, 0b000, 0b001, 0b011}},  // 38
    {{0b110, 0b111, 0b101, 0b001, 0b000, 0b010}},  // 39
    {{0b110, 0b100, 0b000, 0b001, 0b011, 0b111}},  // 40
    {{0b111, 0b101, 0b001, 0b000, 0b010, 0b110}},  // 41
    {{0b101, 0b100, 0b000, 0b010, 0b011, 0b111}},  // 42
    {{0b100, 0b101, 0b001, 0b011, 0b010, 0b110}},  // 43
    {{0b100, 0b110, 0b010, 0b011, 0b001, 0b101}},  // 44
    {{0b101, 0b111, 0b011, 0b010, 0b000, 0b100}},  // 45
    {{0b111, 0b110, 0b010, 0b000, 0b001, 0b101}},  // 46
    {{0b110, 0b111, 0b011, 0b001, 0b000, 0b100}},  // 47
}};

std::optional<int> bldc_number_of(const HallSequence& sequence) {
  for (std::size_t n = 0; n < kBldcPatterns.size(); ++n)
    if (kBldcPatterns[n] == sequence.code_at_sector) return static_cast<int>(n);
  return std::nullopt;
}

bool one_bit_apart(HallCode a, HallCode b) {
  return std::popcount(static_cast<unsigned>(a ^ b)) == 1;
}

// The six codes other than `excluded` and its complement, in cycle order from the smallest.
std::array<HallCode, 6> cycle_without(HallCode excluded) {
  const auto allowed = [&](HallCode c) { return c != excluded && c != (excluded ^ 7); };
  std::array<HallCode, 6> cycle{};
  HallCode first = 0;
  while (!allowed(first)) ++first;
  cycle[0] = first;
  for (std::size_t i = 1; i < 6; ++i) {
    for (HallCode next = 0; next < 8; ++next) {
      const bool is_back = i >= 2 && next == cycle[i - 2];
      if (allowed(next) && one_bit_apart(next, cycle[i - 1]) && !is_back) {
        cycle[i] = next;
        break;
      }
    }
  }
  return cycle;
}

std::array<HallTableRow, 48> build_table() {
  std::array<HallTableRow, 48> rows{};
  std::size_t n = 0;
  for (HallCode excluded : {HallCode{0}, HallCode{1}, HallCode{2}, HallCode{3}}) {
    const auto cycle = cycle_without(excluded);
    std::array<HallCode, 6> starts = cycle;
    std::sort(starts.begin(), starts.end());
    for (HallCode start : starts) {
      const auto at = static_cast<std::size_t>(std::find(cycle.begin(), cycle.end(), start) - cycle.begin());
      std::array<HallSequence, 2> both{};
      for (std::size_t k = 0; k < 6; ++k) {
        both[0].code_at_sector[k] = cycle[(at + k) % 6];
        both[1].code_at_sector[k] = cycle[(at + 6 - k) % 6];
      }
      if (both[1].code_at_sector[1] < both[0].code_at_sector[1]) std::swap(both[0], both[1]);
      for (const HallSequence& sequence : both) {
        HallTableRow& row = rows[n++];
        row.sequence = sequence;
        row.unused_low = excluded;
        row.layout = excluded == 0 ? HallLayout::Deg120 : HallLayout::Deg60;
        row.bldc_pattern = bldc_number_of(sequence);
      }
    }
  }
  return rows;
}

}  // namespace

HallSequence bldc_pattern_25() {
  return HallSequence{{01, 05, 04, 06, 02, 03}};
}

std::span<const HallTableRow, 48> hall_table() {
  static const std::array<HallTableRow, 48> table = build_table();
  return table;
}

std::optional<std::size_t> find_hall_row(const HallSequence& sequence) {
  const auto table = hall_table();
  for (std::size_t i = 0; i < table.size(); ++i) {
    if (table[i].sequence == sequence) return i;
  }
  return std::nullopt;
}

HallCode apply_rewiring(const HallRewiring& rewiring, HallCode code) {
  HallCode out = 0;
  for (int input = 1; input <= 3; ++input) {
    bool level = (code & hall_bit(rewiring.source[input - 1])) != 0;
    if (rewiring.invert[input - 1]) level = !level;
    if (level) out |= hall_bit(input);
  }
  return out;
}

bool HallRewiring::is_identity() const {
  return source == std::array<int, 3>{1, 2, 3} && invert == std::array<bool, 3>{false, false, false};
}

std::string HallRewiring::describe() const {
  std::string text;
  for (int input = 1; input <= 3; ++input) {
    if (!text.empty()) text += ", ";
    text += "hall" + std::to_string(input) + " <- sensor " + std::to_string(source[input - 1]);
    if (invert[input - 1]) text += " inverted";
  }
  return text;
}

HallRewiring rewiring_to_pattern_25(const HallSequence& sequence) {
  const HallSequence target = bldc_pattern_25();
  HallRewiring candidate;
  std::array<int, 3> order{1, 2, 3};
  do {
    for (unsigned mask = 0; mask < 8; ++mask) {
      candidate.source = order;
      candidate.invert = {(mask & 4) != 0, (mask & 2) != 0, (mask & 1) != 0};
      HallSequence seen{};
      for (std::size_t k = 0; k < 6; ++k)
        seen.code_at_sector[k] = apply_rewiring(candidate, sequence.code_at_sector[k]);
      if (seen == target) return candidate;
    }
  } while (std::next_permutation(order.begin(), order.end()));
  return HallRewiring{};  // unreachable for the 48 sequences (tested)
}

std::string hall_code_text(HallCode code) {
  return {static_cast<char>('0' + ((code >> 2) & 1)), static_cast<char>('0' + ((code >> 1) & 1)),
          static_cast<char>('0' + (code & 1))};
}

}  // namespace i20::commission
