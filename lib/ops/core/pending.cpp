// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/pending.hpp"

#include "ops/core/read.hpp"

namespace i20::ops {
std::vector<const params::Param*> nv_cells_with_twins(const params::ParamDb& db) {
  std::vector<const params::Param*> cells;
  for (const auto& p : db.all())
    if (p.is_nv() && !p.twin.empty() && db.find(p.twin)) cells.push_back(&p);
  return cells;
}

std::vector<std::string> pending_nv_values(const params::ParamDb& db, const profile::RawValues& values) {
  std::vector<std::string> pending;
  for (const auto* p : nv_cells_with_twins(db)) {
    const auto nv = values.find(p->name);
    const auto working = values.find(p->twin);
    if (nv != values.end() && working != values.end() && nv->second != working->second)
      pending.push_back(p->name);
  }
  return pending;
}

std::vector<std::string> pending_nv_values(Amp& amp) {
  const params::ParamDb& db = amp.db();
  std::vector<const params::Param*> cells;
  for (const auto* p : nv_cells_with_twins(db)) cells.insert(cells.end(), {p, &db.get(p->twin)});
  profile::RawValues facts;
  for (const auto& r : read_values(amp, cells))
    if (r.fact()) facts[r.param->name] = *r.raw;
  return pending_nv_values(db, facts);
}

}  // namespace i20::ops
