// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/read.hpp"

#include <algorithm>

namespace i20::ops {

std::vector<Reading> read_values(Amp& amp, std::span<const params::Param* const> params,
                                 Unconfirmed unconfirmed) {
  std::vector<Reading> out;
  std::vector<const params::Param*> wanted;
  for (const params::Param* p : params) {
    Reading r{p, std::nullopt, amp.db().address_confirmed(*p) && p->address.has_value(),
              amp.unconfirmed_reason(*p)};
    if (p->address && (r.confirmed || unconfirmed == Unconfirmed::Read)) wanted.push_back(p);
    out.push_back(std::move(r));
  }
  if (wanted.empty()) return out;
  const auto values = amp.with_retries([&] { return amp.device().read(wanted); });
  std::size_t next = 0;
  for (auto& r : out)
    if (next < wanted.size() && r.param == wanted[next]) r.raw = values[next++].raw;
  return out;
}

std::vector<Reading> read_values(Amp& amp, const std::vector<std::string>& names, Unconfirmed unconfirmed) {
  std::vector<const params::Param*> params;
  for (const auto& name : names) params.push_back(&amp.db().get(name));
  return read_values(amp, params, unconfirmed);
}

std::vector<Reading> read_all(Amp& amp, Unconfirmed unconfirmed) {
  std::vector<const params::Param*> params;
  for (const auto& p : amp.db().all())
    if (p.address) params.push_back(&p);
  return read_values(amp, params, unconfirmed);
}

std::string unknown_text(const Reading& reading) {
  return "unknown (" + (reading.reason.empty() ? std::string("not read") : reading.reason) + ")";
}

Outcome reading_outcome(std::span<const Reading> readings) {
  const bool all_read = std::ranges::all_of(readings, [](const Reading& r) { return r.raw.has_value(); });
  return all_read ? Outcome::Done : Outcome::Refused;
}

}  // namespace i20::ops
