// SPDX-License-Identifier: GPL-2.0-or-later
// Which memory of the card a profile entry writes (a profile's `target:` key; not a card,
// which --target names, nor an Ethernet channel, which is eth::EthTarget).
//
// The 8I20 keeps two copies of each setup parameter: the working (RAM) value the drive uses
// now, and the NV (EEPROM) value loaded into it at reset (manual, DRIVE PARAMETER SETUP).
#pragma once

#include <optional>
#include <string_view>

namespace i20::profile {

enum class Memory {
  Nv,       // the EEPROM parameter only: takes effect after the next reset
  Working,  // the working parameter only: takes effect now, lost at power-down
  Both,     // the EEPROM parameter and its working twin
};

const char* to_string(Memory target);
// "nv", "working" or "both"; nullopt for anything else.
std::optional<Memory> parse_memory(std::string_view text);

}  // namespace i20::profile
