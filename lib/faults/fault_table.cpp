// SPDX-License-Identifier: GPL-2.0-or-later
#include "faults/fault_table.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <optional>

#include "params/closest.hpp"
#include "params/text.hpp"

namespace i20::faults {
namespace {

using params::lower;

bool same_text(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// "hm2_7i96s.0.8i20.0.0.fault.no-enable" (a pin as halshow shows it) -> "fault.no-enable".
std::string_view pin_part(std::string_view key) {
  if (key.size() < 4 || !same_text(key.substr(0, 4), "hm2_")) return key;
  for (std::string_view reg : {".fault.", ".status."})
    for (std::size_t at = 0; (at = key.find(reg.substr(1), at)) != std::string_view::npos; ++at)
      if (at > 0 && key[at - 1] == '.') return key.substr(at);
  return key;
}

bool names(const BitInfo& b, std::string_view key) {
  key = pin_part(key);
  return same_text(b.slug, key) || same_text(b.name, key) ||
         (!b.linuxcnc_pin.empty() && same_text(b.linuxcnc_pin, key));
}

// "8" -> 8; anything else (including "08x" or "99") -> no bit.
std::optional<unsigned> bit_number(std::string_view key) {
  unsigned value = 0;
  const auto [ptr, ec] = std::from_chars(key.data(), key.data() + key.size(), value);
  if (key.empty() || ec != std::errc() || ptr != key.data() + key.size() || value > 15) return std::nullopt;
  return value;
}

}  // namespace

const std::vector<BitInfo>& FaultTable::bits(Register reg) const {
  return reg == Register::Fault ? fault_ : status_;
}

const std::vector<std::string>& FaultTable::notes(Register reg) const {
  return reg == Register::Fault ? fault_notes_ : status_notes_;
}

const BitInfo* FaultTable::find(Register reg, unsigned bit) const {
  const auto& list = bits(reg);
  const auto it = std::ranges::find(list, bit, &BitInfo::bit);
  return it == list.end() ? nullptr : &*it;
}

const BitInfo* FaultTable::find(std::string_view key) const {
  if (bit_number(key)) return nullptr;  // a bare number is ambiguous without a register
  if (const BitInfo* b = find(Register::Fault, key)) return b;
  return find(Register::Status, key);
}

const BitInfo* FaultTable::find(Register reg, std::string_view key) const {
  if (const auto bit = bit_number(key)) return find(reg, *bit);
  const auto& list = bits(reg);
  const auto it = std::ranges::find_if(list, [&](const BitInfo& b) { return names(b, key); });
  return it == list.end() ? nullptr : &*it;
}

const BitInfo& FaultTable::get(Register reg, std::string_view key) const {
  if (const BitInfo* b = find(reg, key)) return *b;
  const auto reg_name = std::string(to_string(reg));
  std::string message;
  if (const auto bit = bit_number(key)) {
    message = reg_name + " bit " + std::to_string(*bit) + " is reserved: the 8I20 manual does not define it";
  } else if (const BitInfo* other = find(key)) {
    // Built by appending: GCC 12's -O3 -Wrestrict misfires on `"'" + std::string(key) + ...`.
    message = "'";
    message += key;
    message += "' is a " + std::string(to_string(other->reg)) + " bit, not a " + reg_name + " bit";
  } else {
    message = "unknown " + lower(reg_name) + " bit '" + std::string(key) + "'";
  }
  auto near = suggestions(reg, key);
  if (!near.empty()) {
    message += ": did you mean ";
    for (std::size_t i = 0; i < near.size(); ++i)
      message += (i ? (i + 1 == near.size() ? " or " : ", ") : "") + near[i];
    message += "?";
  } else {
    message += " (the " + reg_name + " bits are listed in params/faults.yaml)";
  }
  throw UnknownBit(message, std::move(near));
}

std::uint16_t FaultTable::defined_bits(Register reg) const {
  std::uint16_t out = 0;
  for (const auto& b : bits(reg)) out |= b.mask();
  return out;
}

std::uint16_t FaultTable::maskable_bits() const {
  std::uint16_t out = 0;
  for (const auto& b : fault_)
    if (b.maskable) out |= b.mask();
  return out;
}

double FaultTable::fixed_limit(std::string_view key) const {
  const BitInfo* b = find(Register::Fault, key);
  if (b && b->live_check && b->live_check->threshold_value) return *b->live_check->threshold_value;
  throw FaultFileError(source_ + ": FAULT bit '" + std::string(key) +
                       "' has no live_check with a fixed limit (above: or below: a number)");
}

std::vector<std::string> FaultTable::suggestions(Register reg, std::string_view key, std::size_t max) const {
  if (bit_number(key)) return {};
  // Every spelling of a bit counts; the slug, the CLI's word, is what is suggested.
  std::vector<params::Candidate> candidates;
  for (const auto& b : bits(reg)) candidates.push_back({b.slug, {b.slug, b.name}});
  return params::closest(key, candidates, max);
}

}  // namespace i20::faults
