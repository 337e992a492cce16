// SPDX-License-Identifier: GPL-2.0-or-later
#include "profile/effective.hpp"

#include "params/value.hpp"

namespace i20::profile {
namespace {

const char* to_string(Origin origin) {
  switch (origin) {
    case Origin::Profile: return "profile";
    case Origin::Card: return "card";
    case Origin::Default: return "default";
  }
  return "?";
}

}  // namespace

std::string Effective::describe() const {
  return param->name + " " + params::format_engineering(*param, raw) + " (" + to_string(origin) + ")";
}

EffectiveValues::EffectiveValues(const Profile& profile, const params::ParamDb& db, const RawValues* card)
    : profile_(profile), db_(db), card_(card) {
  for (const auto& w : cell_writes(profile, db)) written_[w.cell] = {w.raw, w.setting};
}

std::optional<Effective> EffectiveValues::get(const std::string& cell) const {
  const params::Param& p = db_.get(cell);
  if (const auto it = written_.find(p.name); it != written_.end())
    return Effective{&p, it->second.first, Origin::Profile, &profile_.settings[it->second.second]};
  if (card_)
    if (const auto it = card_->find(p.name); it != card_->end())
      return Effective{&p, it->second, Origin::Card};
  // A working parameter starts from its NV twin at reset, so the twin's default is its own.
  std::optional<std::int64_t> fallback = p.default_value;
  if (!fallback && !p.twin.empty()) fallback = db_.get(p.twin).default_value;
  if (!fallback) return std::nullopt;
  return Effective{&p, *fallback, Origin::Default};
}

bool EffectiveValues::touches(params::Space space) const {
  for (const auto& [cell, value] : written_)
    if (db_.get(cell).space == space) return true;
  return false;
}

}  // namespace i20::profile
