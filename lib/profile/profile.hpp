// SPDX-License-Identifier: GPL-2.0-or-later
// A motor / current-loop profile: who it is for (metadata) and the parameter values it sets.
//
// Values are held as the card's raw integers (already parsed from engineering units by the
// loader through the parameter database), so every later step compares exactly what
// travels on the wire. The YAML schema is described in profiles/README.md.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "params/param_db.hpp"
#include "profile/memory.hpp"

namespace i20::profile {

// What the manual asks you to know about the motor before setting MAXCURRENT, plus what
// the tuning calculator needs. All optional: a profile for the power stage alone has none.
struct MotorInfo {
  std::string make;
  std::string model;
  std::optional<double> continuous_current_a;  // RMS, per the motor's rating plate
  std::optional<double> peak_current_a;        // RMS, the motor's maximum (demagnetisation) rating
  std::optional<double> phase_resistance_ohm;  // line to neutral (half the line-to-line value)
  std::optional<double> phase_inductance_h;    // line to neutral (half the line-to-line value)
  // As data sheets give them, measured between two motor leads. The loader derives the
  // phase values (half of these: the equivalent star, for star and delta windings alike).
  std::optional<double> line_to_line_resistance_ohm;
  std::optional<double> line_to_line_inductance_h;
  // Documentation for the LinuxCNC side of the machine (e.g. the pole count a commutation
  // or bldc configuration asks for); the 8I20 does not use it. Given as poles or pole_pairs.
  std::optional<int> poles;

  bool empty() const;
};

struct SupplyInfo {
  std::string description;
  std::optional<double> bus_voltage_v;  // nominal DC bus voltage the supply holds

  bool empty() const { return description.empty() && !bus_voltage_v; }
};

// The 8I20 a saved profile or backup was read from (`origin:`): `profile undo` restores a
// backup only onto that card unless forced. Profiles written by hand have none.
struct AmpOrigin {
  std::optional<std::uint32_t> unit_number;  // UNITNUMBER
  std::optional<std::uint16_t> firmware;     // SWREVISION
  std::string card;                          // the card's name, "8I20"

  bool empty() const { return !unit_number && !firmware && card.empty(); }
};

// One `parameters:` entry.
struct Setting {
  std::string name;  // the database's spelling of the key, e.g. "NVMAXCURRENT"
  std::int64_t raw = 0;
  std::optional<Memory> target;  // per-entry target, if the entry gives one
  int line = 0;                  // 1-based line in the source file, 0 if not from a file
};

struct Profile {
  std::string source;  // file name (or label) used in messages
  std::string name;
  std::string description;
  MotorInfo motor;
  SupplyInfo supply;
  std::string notes;
  AmpOrigin origin;
  std::optional<Memory> target;  // profile-wide target; entries may override it
  std::vector<Setting> settings;
  std::vector<std::string> comments;  // written as '#' lines on top (provenance); not read back

  // Entry target, else profile target, else the space the key names (NV... -> nv).
  Memory target_of(const Setting& setting, const params::ParamDb& db) const;
  // "file:line" of an entry (just the file when the line is unknown).
  std::string where(const Setting& setting) const;
};

// One parameter of the card that a profile writes, and the entry that asks for it.
struct CellWrite {
  std::string cell;  // e.g. "NVBRAKEONV" or "BRAKEONV"
  std::int64_t raw = 0;
  std::size_t setting = 0;  // index into Profile::settings
};

// The cells one entry writes, resolved through its target (both: EEPROM first, then working).
// Throws ProfileError if the target cannot be met (no twin in the asked-for space).
std::vector<std::string> cells_of(const Profile& profile, const Setting& setting, const params::ParamDb& db);
// Every cell the profile writes, in profile order. Throws ProfileError when two entries
// write the same cell.
std::vector<CellWrite> cell_writes(const Profile& profile, const params::ParamDb& db);
// The same profile with every entry aimed at `target` (e.g. to try a profile live first).
// Throws ProfileError if an entry cannot take that target.
Profile retarget(Profile profile, Memory target, const params::ParamDb& db);

}  // namespace i20::profile
