// SPDX-License-Identifier: GPL-2.0-or-later
#include "sim/param_map.hpp"

namespace i20::sim {

RegisterMap register_map_from(const params::ParamDb& db) {
  const RegisterMap fallback = RegisterMap::builtin();
  RegisterMap map;
  for (const auto& p : db.all()) {
    if (!p.address) continue;  // the card has it somewhere, but the database does not know where
    Register r{.name = p.name,
               .space = p.space == params::Space::Eeprom ? Space::Eeprom : Space::Ram,
               .address = *p.address,
               .width_bits = p.width_bits,
               .is_signed = p.is_signed,
               .default_value = p.default_value,
               .read_only = p.access == params::Access::ReadOnly,
               .twin = p.twin};
    if (!r.default_value)
      if (const auto* b = fallback.find(r.name)) r.default_value = b->default_value;
    map.set(std::move(r));
  }
  map.set_swrevision(db.simulator_swrevision().value_or(kBuiltinSwRevision));
  map.validate();
  return map;
}

}  // namespace i20::sim
