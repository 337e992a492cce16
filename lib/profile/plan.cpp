// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/plan.hpp"

#include <algorithm>
#include <array>
#include <string_view>
#include <tuple>

#include "params/value.hpp"

namespace i20::profile {
namespace {

// Lowest to highest: the order the thresholds must keep on the bus-voltage axis.
constexpr std::array<std::string_view, 5> kVoltageChain{"BUSUNDERV", "BUSUNDERVMAX", "BRAKEOFFV", "BRAKEONV",
                                                        "BUSOVERV"};
constexpr std::array<std::string_view, 6> kGains{"KQP", "KDP", "KQI", "KDI", "KQIL", "KDIL"};

enum Group {
  kCurrentDown,
  kChainDown,
  kChainUp,
  kGainsDown,
  kGainsUp,
  kOther,
  kCurrentUp,
};

struct Keyed {
  int space;  // 0: EEPROM, 1: working
  int group;
  int rank;  // position within the group; ties keep profile order
  DiffRow row;
};

// The working name of a cell: NVBRAKEONV -> BRAKEONV.
std::string base_name(const params::Param& p) {
  return p.is_nv() && !p.twin.empty() ? p.twin : p.name;
}

int chain_position(std::string_view base) {
  const auto it = std::ranges::find(kVoltageChain, base);
  return it == kVoltageChain.end() ? -1 : static_cast<int>(it - kVoltageChain.begin());
}

// Unknown card values count as increases: the conservative side of each rule.
bool decreases(const DiffRow& row) {
  return row.card_raw && row.profile_raw < *row.card_raw;
}

Keyed key_of(DiffRow row, const params::ParamDb& db) {
  const params::Param& p = db.get(row.cell);
  const std::string base = base_name(p);
  const bool down = decreases(row);
  Keyed k{p.is_nv() ? 0 : 1, kOther, 0, std::move(row)};
  if (base == "MAXCURRENT") {
    k.group = down ? kCurrentDown : kCurrentUp;
  } else if (const int pos = chain_position(base); pos >= 0) {
    k.group = down ? kChainDown : kChainUp;
    k.rank = down ? pos : -pos;
  } else if (std::ranges::find(kGains, base) != kGains.end()) {
    k.group = down ? kGainsDown : kGainsUp;
  }
  return k;
}

}  // namespace

std::vector<DiffRow> safe_order(std::vector<DiffRow> steps, const params::ParamDb& db) {
  std::vector<Keyed> keyed;
  for (auto& row : steps) keyed.push_back(key_of(std::move(row), db));
  std::ranges::stable_sort(keyed, [](const Keyed& a, const Keyed& b) {
    return std::tie(a.space, a.group, a.rank) < std::tie(b.space, b.group, b.rank);
  });
  std::vector<DiffRow> out;
  for (auto& k : keyed) out.push_back(std::move(k.row));
  return out;
}

std::string unsafe_step(const Plan& plan, const params::ParamDb& db, const RawValues& card) {
  constexpr std::pair<std::string_view, std::string_view> kPairs[] = {
      {"BRAKEOFFV", "BRAKEONV"}, {"BUSUNDERV", "BUSOVERV"}, {"BUSUNDERV", "BUSUNDERVMAX"}};
  struct Pair {
    std::string low, high;
  };
  std::vector<Pair> pairs;
  for (const auto& [low, high] : kPairs) {
    const params::Param* lo = db.find(low);
    const params::Param* hi = db.find(high);
    if (!lo || !hi) continue;
    pairs.push_back({lo->name, hi->name});
    if (!lo->twin.empty() && !hi->twin.empty()) pairs.push_back({lo->twin, hi->twin});
  }
  const auto in_order = [](const RawValues& state, const Pair& p) {
    const auto lo = state.find(p.low);
    const auto hi = state.find(p.high);
    return lo == state.end() || hi == state.end() || lo->second < hi->second;
  };
  RawValues state = card;
  for (const auto& step : plan.steps) {
    state[step.cell] = step.profile_raw;
    for (const auto& p : pairs) {
      if (in_order(state, p) || !in_order(card, p)) continue;
      const auto text = [&](const std::string& cell) {
        return cell + " " + params::format_engineering(db.get(cell), state.at(cell));
      };
      return "after writing " + step.cell + " = " + step.profile_text + ": " + text(p.low) + " is not below " +
             text(p.high);
    }
  }
  return {};
}

Plan make_plan(const Profile& profile, const params::ParamDb& db, const RawValues& card) {
  Plan plan;
  std::vector<DiffRow> changes;
  for (auto& row : diff(profile, db, card)) {
    if (row.equal) {
      plan.unchanged.push_back(std::move(row));
    } else {
      plan.reset_needed = plan.reset_needed || row.nv;
      changes.push_back(std::move(row));
    }
  }
  plan.steps = safe_order(std::move(changes), db);
  return plan;
}

}  // namespace i20::profile
