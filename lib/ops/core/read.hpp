// SPDX-License-Identifier: GPL-2.0-or-later
// Honest reads: a value is shown as a fact only when its address is confirmed for the
// card's firmware (a public fact, the card's own RPC table, or an overlay for that
// SWREVISION). Anything else is "unknown", with the reason, unless the user asks to see
// the raw word at the guessed address, which is then marked as such.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "ops/core/amp.hpp"
#include "ops/core/outcome.hpp"
#include "params/param.hpp"

namespace i20::ops {

struct Reading {
  const params::Param* param = nullptr;  // in the card's resolved database
  std::optional<std::int64_t> raw;       // nullopt: not read, see `reason`
  bool confirmed = false;                // the address is confirmed for this firmware
  std::string reason;  // why it is not a fact: "address not confirmed for SWREVISION 0x1234"

  bool fact() const { return raw && confirmed; }
};

enum class Unconfirmed {
  Skip,  // not read: reported unknown
  Read,  // read and returned with confirmed = false (the user asked: --allow-unverified)
};

// One exchange for all of them (NV values inside NV access mode), repeated per the card's
// retry policy when the line garbles a reply. Parameters without any address are unknown.
std::vector<Reading> read_values(Amp& amp, std::span<const params::Param* const> params,
                                 Unconfirmed unconfirmed = Unconfirmed::Skip);
// By name (database or alias spelling); UnknownParameter before anything is sent.
std::vector<Reading> read_values(Amp& amp, const std::vector<std::string>& names,
                                 Unconfirmed unconfirmed = Unconfirmed::Skip);
// Every parameter the database places: `i20 dump`, `profile save`, `report`.
std::vector<Reading> read_all(Amp& amp, Unconfirmed unconfirmed = Unconfirmed::Skip);

// A read's outcome: Refused when any value could not be read as asked (its address is not
// confirmed and --allow-unverified was not given, or it has none), Done otherwise.
Outcome reading_outcome(std::span<const Reading> readings);

// "unknown (address not confirmed for SWREVISION 0x1234)".
std::string unknown_text(const Reading& reading);

}  // namespace i20::ops
