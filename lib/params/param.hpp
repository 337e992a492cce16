// SPDX-License-Identifier: GPL-2.0-or-later
// One parameter of the 8I20 as the database describes it.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace i20::params {

enum class Space { Ram, Eeprom };
enum class Access { ReadOnly, ReadWrite };

// Where an address comes from and on which firmware it has been confirmed.
struct Provenance {
  std::string source;
  bool confirmed_on_all = false;            // a public fact for every revision
  std::vector<std::uint16_t> confirmed_on;  // SWREVISION values it was confirmed on
};

// Another name a parameter answers to: LinuxCNC's hostmot2 name for it (docs/facts.md s2).
// hostmot2 splits the 32-bit gains NVKQI/NVKDI into two 16-bit parameters; such an alias
// names one half. i20 reads and writes the whole value only, so a half alias is recognised
// (to say so) but resolves to nothing.
struct Alias {
  enum class Part { Whole, Low16, High16 };
  std::string name;  // as the YAML spells it, e.g. "nvmaxcurrent"
  Part part = Part::Whole;
};

struct Param {
  std::string name;
  Space space = Space::Ram;
  std::optional<std::uint16_t> address;  // nullopt: not known
  unsigned width_bits = 16;              // 8, 16 or 32
  bool is_signed = false;
  std::string unit;    // "V", "A", "degC", "deg" or "" for raw counts
  double scale = 1.0;  // engineering value = raw * scale
  std::int64_t min = 0;
  std::int64_t max = 0;
  std::vector<std::int64_t> allowed;  // if not empty, the only raw values accepted
  Access access = Access::ReadOnly;
  std::optional<std::int64_t> default_value;
  std::string twin;  // NV twin of a working parameter, or working twin of an NV one
  std::string description;
  Provenance provenance;
  std::string guard;           // non-empty: writing needs --force, and this says why
  bool self_clearing = false;  // the card resets it itself (CLEARFAULT): no read-back verify
  bool hex = false;            // shown as 0x and width/4 digits (bit registers: FAULT, STATUS)
  std::string origin;          // "file:line" of the entry (or of its last override)
  std::vector<Alias> aliases;  // other names, matched case-insensitively like the name
  // What raw values mean, where the manual gives a table (NVBAUDRATE 9 = 2.5 MBaud).
  std::map<std::int64_t, std::string> labels;

  std::size_t bytes() const { return width_bits / 8; }
  bool writable() const { return access == Access::ReadWrite; }
  bool is_nv() const { return space == Space::Eeprom; }
  // Is the address confirmed for a card reporting this firmware revision?
  // With no revision known only facts confirmed on all revisions count.
  bool address_confirmed(std::optional<std::uint16_t> swrevision) const;
};

const char* to_string(Space space);

}  // namespace i20::params
