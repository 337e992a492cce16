// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/reset.hpp"

#include <algorithm>
#include <exception>

#include "device/errors.hpp"
#include "ops/core/amp_cell_access.hpp"
#include "ops/core/timing.hpp"
#include "profile/validate.hpp"

namespace i20::ops {
namespace {

using profile::Finding;
using profile::Severity;

// The NV cells a reset copies into a working twin the database knows.

// The validator calls a value it judges "(profile)"; here it is what the EEPROM holds.
std::string as_eeprom_value(std::string message) {
  const std::string from = " (profile)";
  for (auto at = message.find(from); at != std::string::npos; at = message.find(from, at))
    message.replace(at, from.size(), " (in the EEPROM)");
  return message;
}

// What the card runs with after the reset: every NV value (pending or already live: a
// power-up may have made a bench setup live before anyone asked for a reset), as a
// profile aimed at the EEPROM, so that the validator judges the whole EEPROM space.
profile::Profile live_after_reset(const ResetJudgement& j) {
  profile::Profile p;
  p.source = "the card's EEPROM";
  p.name = "values the card runs with after a reset";
  for (const auto& [name, raw] : j.nv) p.settings.push_back({name, raw, std::nullopt, 0});
  return p;
}

}  // namespace

std::string ResetJudgement::reason() const {
  std::string text;
  for (const auto& f : findings)
    if (f.severity == Severity::Error)
      text +=
          (text.empty() ? "" : "; ") + (f.key.empty() ? "" : f.key + ": ") + f.message + " [" + f.rule + "]";
  return text;
}

ResetJudgement judge_reset(const params::ParamDb& db, CellAccess& card, bool force,
                           const profile::Profile* planned) {
  return judge_reset(db, card, force, planned, ReadAlready{});
}

ResetJudgement judge_reset(const params::ParamDb& db, CellAccess& card, bool force,
                           const profile::Profile* planned, const ReadAlready& already) {
  std::vector<std::string> names;
  for (const auto* p : nv_cells_with_twins(db)) names.insert(names.end(), {p->name, p->twin});
  if (db.find("BUSV")) names.push_back("BUSV");
  std::vector<std::string> unread;
  for (const auto& name : names)
    if (!already.asked.contains(name)) unread.push_back(name);
  // Cells that are no fact on this firmware are left out; one the card fails to answer for
  // throws (the caller refuses the reset).
  RawValues values = unread.empty() ? RawValues{} : card.read(unread);
  for (const auto& name : names)
    if (const auto it = already.values.find(name); already.asked.contains(name) && it != already.values.end())
      values[name] = it->second;
  ResetJudgement j;
  if (const auto bus = values.find("BUSV"); bus != values.end()) {
    j.measured_bus_v = static_cast<double>(bus->second) * db.get("BUSV").scale;
    values.erase(bus);
  }
  if (planned)
    for (const auto& w : profile::cell_writes(*planned, db))
      if (db.get(w.cell).is_nv()) values[w.cell] = w.raw;
  j.pending = pending_nv_values(db, values);
  for (const auto* p : nv_cells_with_twins(db)) {
    if (values.contains(p->name)) j.nv[p->name] = values.at(p->name);
    if (values.contains(p->name) && !values.contains(p->twin)) j.unknown_live.push_back(p->name);
  }
  const profile::ValidationContext context{&values, force, j.measured_bus_v};
  for (auto& f : profile::validate(live_after_reset(j), db, context)) {
    // The guard is about writing a value; this one is in the EEPROM already.
    if (f.rule == "guarded") continue;
    f.message = as_eeprom_value(std::move(f.message));
    j.findings.push_back(std::move(f));
  }
  return j;
}

void add_reset_findings(std::vector<Finding>& findings, const params::ParamDb& db, CellAccess& card,
                        bool force, const profile::Profile& planned, const ReadAlready& already) {
  std::vector<Finding> extra;
  try {
    extra = judge_reset(db, card, force, &planned, already).findings;
  } catch (const std::exception& e) {
    findings.push_back({Severity::Error, "", "reset-unjudged",
                        std::string("cannot read the EEPROM values a reset would make live, so no reset is "
                                    "judged safe: ") +
                            e.what(),
                        planned.source});
    return;
  }
  for (auto& f : extra) {
    const bool known =
        std::ranges::any_of(findings, [&](const Finding& g) { return g.key == f.key && g.rule == f.rule; });
    if (!known) findings.push_back(std::move(f));
  }
}

ResetRun reset_amp(Amp& amp, bool force) {
  ResetRun run;
  {
    AmpCellAccess access(amp, device::WriteOptions{});
    run.judgement = judge_reset(amp.db(), access, force);
  }
  if (run.judgement.refused()) return run;
  try {
    amp.device().reset(timing::kResetWait);
  } catch (const Error& e) {
    // The reset was sent: the card may be running from its NV values, or not be back.
    if (e.kind() != ErrorKind::Failure) throw;
    throw device::AmpStateError(std::string("the reset was sent, but: ") + e.what() +
                                "; the card may be running from its NV values now");
  }
  run.done = true;
  return run;
}

}  // namespace i20::ops
