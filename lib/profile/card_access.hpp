// The seam between the profile engine and a real (or simulated, or fake) 8I20.
//
// The device layer adapts its Amp8i20 client to this interface; tests use a fake with
// injected failures. The engine relies only on what is written here.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace i20::profile {

// Raw values by database name ("NVBRAKEONV" -> 36000).
using RawValues = std::map<std::string, std::int64_t>;

class CardAccess {
 public:
  virtual ~CardAccess() = default;

  // Reads every named parameter (NV ones from the EEPROM) and returns all of them, or
  // throws i20::Error if any could not be read. Reading never changes the card.
  virtual RawValues read(const std::vector<std::string>& names) = 0;

  // Would write() refuse this value by its own rules (range, guards, addresses not
  // confirmed for this card's firmware)? Throws i20::Error saying why; sends nothing.
  // apply() asks for every planned write before the first one, so a refusal stops it
  // with the card untouched instead of half way. The default accepts everything.
  virtual void check_write(const std::string& name, std::int64_t raw) {
    (void)name;
    (void)raw;
  }

  // Writes one parameter, enforcing the device layer's safety rules (range, guards,
  // unconfirmed addresses), and confirms it by reading it back; NV parameters go through
  // the EEPROM sequence (enter NV mode, write, read back, leave NV mode, also on error).
  // Returns only when the card holds `raw`; throws i20::Error otherwise, in which case the
  // cell may hold the old value, the new one or something else.
  virtual void write(const std::string& name, std::int64_t raw) = 0;

  // Resets the 8I20 so that NV values are loaded into the working parameters. Throws
  // i20::Error if the card does not come back.
  virtual void reset() = 0;

  // One line saying which card this is, for reports and backup provenance, e.g.
  // "8I20 unit 0x00012345, SWREVISION 0xE120, on /dev/ttyUSB0".
  virtual std::string describe() = 0;
};

}  // namespace i20::profile
