// SPDX-License-Identifier: GPL-2.0-or-later
// A profile's NV values as LinuxCNC sets them: HAL `setp` lines for hostmot2's smart-serial
// parameters, or `loadrt setsserial cmd="set ..."` lines (docs/facts.md s2 and s6).
//
// hostmot2 names each 8I20 NV parameter itself (nvmaxcurrent, nvbrakeonv, ...) and carries
// the raw EEPROM word, not engineering units: 19000 is 190 V, 750 is 7.5 A. The 32-bit
// integral gains NVKQI/NVKDI appear as two 16-bit halves, nvkqilo (low) and nvkqihi (high).
// The names are the database's aliases (params/8i20.yaml), the one place they are written.
// Pure: no I/O, nothing printed.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "params/param_db.hpp"
#include "profile/profile.hpp"

namespace i20::profile {

// Which bits of a database parameter one hostmot2 parameter holds.
using HalPart = params::Alias::Part;

// One NV parameter as hostmot2 names it (LinuxCNC sserial.h, hm2_8i20_globals).
struct Hostmot2Parameter {
  std::string hal_name;  // e.g. "nvkqilo"
  std::string db_name;   // e.g. "NVKQI"
  HalPart part = HalPart::Whole;
};

// The hostmot2 parameters of an EEPROM parameter, the low half before the high one (the
// order of their addresses); empty when hostmot2 has none (NVDEADZONE) or for RAM ones.
std::vector<Hostmot2Parameter> hostmot2_names_of(const params::Param& param);
// Every NV parameter hostmot2 has, in database order.
std::vector<Hostmot2Parameter> hostmot2_nv_parameters(const params::ParamDb& db);

// "hm2_7i96s.0.8i20.0.0" (board, board number, sserial port, channel), or
// "hm2_8i20.001f" (hostmot2's use_serial_numbers=1 form). Throws Error (BadInput) for
// anything else: the name ends up inside a halcmd line and a quoted setsserial argument.
void check_hal_device(std::string_view device);

// One `setp`: a hostmot2 parameter, its raw value, and the profile entry it comes from.
struct HalSetting {
  std::string hal_name;  // "nvkqilo"
  std::uint32_t value = 0;
  std::string db_name;  // "NVKQI"
  std::int64_t db_raw = 0;
  HalPart part = HalPart::Whole;
};

struct Hostmot2Values {
  std::vector<HalSetting> settings;  // in profile order; a 32-bit gain gives lo then hi
  std::vector<std::string> skipped;  // why an entry is not exported, one line each
};

// The profile's EEPROM cells in hostmot2 terms. Working-only entries and NV parameters
// hostmot2 has no name for are listed in `skipped`. Throws ProfileError when nothing is
// left to export (e.g. a profile that targets only the working values).
Hostmot2Values hostmot2_values(const Profile& profile, const params::ParamDb& db);

struct ExportOptions {
  std::string device = "hm2_7i96s.0.8i20.0.0";
  std::string source;  // shown in the header comment, e.g. the profile file
};

// `setp DEVICE.NAME VALUE` lines, each after a comment with the value in engineering
// units, under a header saying what the numbers are.
std::string hal_text(const Profile& profile, const params::ParamDb& db, const ExportOptions& options);
// The same values as `loadrt setsserial cmd="set DEVICE.NAME VALUE"` lines for halrun, each
// followed by `unloadrt setsserial` so the next one can load.
std::string setsserial_text(const Profile& profile, const params::ParamDb& db, const ExportOptions& options);

// Reads exported text back (either form): database name -> raw value, the halves of a
// 32-bit gain joined again. Lines for another device, comments and other HAL commands are
// ignored; a half without its partner, an unknown nv name or a malformed number throws
// Error (BadInput) naming the line.
std::map<std::string, std::int64_t> parse_exported(std::string_view text, std::string_view device,
                                                   const params::ParamDb& db);

}  // namespace i20::profile
