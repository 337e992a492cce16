// SPDX-License-Identifier: GPL-2.0-or-later
#include "params/param.hpp"

#include <algorithm>

namespace i20::params {

bool Param::address_confirmed(std::optional<std::uint16_t> swrevision) const {
  if (!address) return false;
  if (provenance.confirmed_on_all) return true;
  return swrevision &&
         std::ranges::find(provenance.confirmed_on, *swrevision) != provenance.confirmed_on.end();
}

const char* to_string(Space space) {
  return space == Space::Ram ? "ram" : "eeprom";
}

}  // namespace i20::params
