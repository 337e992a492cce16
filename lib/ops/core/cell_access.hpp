// SPDX-License-Identifier: GPL-2.0-or-later
// The seam between the write transaction and a real (or simulated, or fake) 8I20.
//
// AmpCellAccess adapts an open ops::Amp to it; tests use a fake with injected failures.
// The transaction relies only on what is written here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "profile/raw_values.hpp"

namespace i20::ops {

using profile::RawValues;

class CellAccess {
 public:
  virtual ~CellAccess() = default;

  // Reads every named parameter (NV ones from the EEPROM) and returns all of them, or
  // throws i20::Error if any could not be read. Reading never changes the card. Names the
  // card cannot read as a fact (address not confirmed for its firmware) are left out of
  // the result rather than read: a guess is not a value.
  virtual RawValues read(const std::vector<std::string>& names) = 0;

  // Would write() refuse this value by its own rules (range, guards, addresses not
  // confirmed for this card's firmware)? Throws i20::Error saying why; sends nothing.
  // The transaction asks for every planned write before the first one, so a refusal stops
  // it with the card untouched instead of half way. The default accepts everything.
  virtual void check_write(const std::string& name, std::int64_t raw) {
    (void)name;
    (void)raw;
  }

  // Writes one parameter and confirms it by reading it back; NV parameters go through
  // the EEPROM sequence (NV mode confirmed before the data write and after it, left on
  // every path). Returns only when the card holds `raw`; throws i20::Error otherwise, in
  // which case the cell may hold the old value, the new one or something else.
  virtual void write(const std::string& name, std::int64_t raw) = 0;

  // Resets the 8I20 so that NV values are loaded into the working parameters. Throws
  // i20::Error if the card does not come back.
  virtual void reset() = 0;
  // From now on the transaction only restores what it wrote and reads it back: the way
  // back, which the operation's deadline does not cut short (it has a bound of its own).
  virtual void way_back() {}

  // One line saying which card this is, for reports and backup provenance, e.g.
  // "8I20 unit 0x00012345, SWREVISION 0xE120, on /dev/ttyUSB0".
  virtual std::string describe() = 0;

  // Things the card did that the user must hear about (it reset itself during a write,
  // the tool reset it to clear a stray write, ...), in order; the transaction copies them
  // into its result.
  virtual std::vector<std::string> events() const { return {}; }
};

}  // namespace i20::ops
