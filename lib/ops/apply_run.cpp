// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/apply_run.hpp"

#include <algorithm>
#include <chrono>
#include <exception>

#include "device/errors.hpp"
#include "faults/bit_info.hpp"
#include "lbp/bytes.hpp"
#include "ops/core/amp_cell_access.hpp"
#include "ops/core/failure.hpp"
#include "ops/core/pending.hpp"
#include "ops/core/read.hpp"
#include "ops/reset.hpp"
#include "ops/core/timing.hpp"
#include "ops/undo.hpp"
#include "profile/backup.hpp"
#include "profile/validate.hpp"

namespace i20::ops {
namespace {

using faults::kResetCauseBits;
using faults::kStatusExtr;
using faults::kStatusSwr;
using faults::kStatusWdto;

// STATUS, where this card's map confirms it (a wrong address would report resets that
// never happened).
std::optional<std::int64_t> sticky_status(Amp& c) {
  try {
    const auto r = read_values(c, std::vector<std::string>{"STATUS"});
    if (r.front().fact()) return r.front().raw;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

std::string reset_names(std::int64_t bits) {
  std::string names;
  const std::pair<std::int64_t, const char*> all[] = {{kStatusWdto, "WDTO, DSP watchdog"},
                                                      {kStatusSwr, "SWR, software reset"},
                                                      {kStatusExtr, "EXTR, power-up"}};
  for (const auto& [bit, name] : all)
    if (bits & bit) names += (names.empty() ? "" : "; ") + std::string(name);
  return names;
}

// A reset in the middle of a transaction reloads every working value from the EEPROM as it
// was then, half written: neither the old values nor the new ones. Say so.
void check_card_reset(Amp& c, std::optional<std::int64_t> before, TargetRun& run) {
  if (!before) return;
  const auto after = sticky_status(c);
  if (!after) return;
  std::int64_t fresh = *after & ~*before & kResetCauseBits;
  // Software resets the tool asked for itself (apply --reset, clearing a stray write).
  const bool ours = run.result->reset_done || !run.result->events.empty();
  if (ours) fresh &= ~std::int64_t{kStatusSwr};
  if (fresh == 0) return;
  run.card_reset = "the card reset itself during the change (STATUS " + reset_names(fresh) +
                   "): its working values were reloaded from the EEPROM as it was at that moment";
}

// A card that went silent during the change and answered again may have been power cycled,
// which leaves no new STATUS bit (EXTR is set from the first power-up on). Its working
// values then changed by themselves: a working twin of an EEPROM cell the profile writes
// that no longer holds what it held before the first write, and that the profile did not
// write itself, can only have been reloaded from the EEPROM.
void check_silent_reset(Amp& c, const ApplyJob& job, std::size_t silences_before, TargetRun& run) {
  if (!run.card_reset.empty() || c.silences_ended() == silences_before) return;
  // A reset the tool did (apply --reset) or already told (events) explains the change.
  if (run.result->reset_done || !run.result->events.empty()) return;
  std::vector<std::string> written;
  for (const auto& w : profile::cell_writes(*job.profile, c.db())) written.push_back(w.cell);
  std::vector<std::string> names;
  for (const auto& [name, raw] : run.result->working_before)
    if (std::ranges::find(written, name) == written.end()) names.push_back(name);
  if (names.empty()) return;
  std::string changed;
  try {
    for (const auto& r : read_values(c, names))
      if (r.raw && *r.raw != run.result->working_before.at(r.param->name))
        changed.append(changed.empty() ? "" : ", ").append(r.param->name);
  } catch (const std::exception&) {
    return;  // the card is silent again: settle() says what that means
  }
  if (changed.empty()) return;
  run.card_reset =
      "the card reset itself during the change (it stopped answering for a while, and its working " +
      changed +
      " changed meanwhile; a power cycle sets no new STATUS bit): its working values were "
      "reloaded from the EEPROM as it was at that moment";
}

// The card reset itself mid-change, so its working values came from the EEPROM half
// written; the EEPROM has been restored since. One more reset makes the working values the
// restored ones again, instead of a mix nobody asked for.
void reload_restored_values(Amp& c, TargetRun& run) {
  try {
    c.device().reset(timing::kResetWait);
    run.result->events.push_back(
        "after restoring the EEPROM the tool reset the card once more, so its working values are the "
        "restored "
        "ones, not the half-written EEPROM's it had reloaded by itself");
    run.card_reset.clear();
  } catch (const Error& e) {
    run.outcome = Outcome::Uncertain;
    run.result->reason += std::string("; the card reset itself meanwhile, and resetting it again failed (") +
                          e.what() + "): its working values may come from the half-written EEPROM";
  }
}

// Every NV value on the card whose working twin holds something else after the run, not
// only the profile's: an earlier write never followed by a reset is not live either. A
// working cell the profile itself set (target working) differs from its EEPROM twin on
// purpose: that twin is not an EEPROM value waiting to go live.
void check_live(Amp& c, const ApplyJob& job, TargetRun& run) {
  const auto& r = *run.result;
  if ((r.outcome != Outcome::Done && r.outcome != Outcome::NothingToDo) || r.reset_done) return;
  try {
    std::vector<std::string> set_live;
    for (const auto& w : profile::cell_writes(*job.profile, c.db()))
      if (const params::Param& p = c.db().get(w.cell); !p.is_nv()) set_live.push_back(p.twin);
    for (auto& name : pending_nv_values(c))
      if (std::ranges::find(set_live, name) == set_live.end()) run.not_live.push_back(std::move(name));
  } catch (const std::exception&) {
    // Best effort: the advice below the outcome is then the transaction's reset_needed alone.
  }
}

// A read after the change (the checks above) may have died with NV mode on: the outcome is
// not "done" while the card may still be in it.
void settle(Amp& amp, TargetRun& run) {
  try {
    if (const auto mode = amp.settle(); !mode.empty())
      run.result->events.push_back("the line failed while the card was in " + mode +
                                   "; it answered again and left it");
  } catch (const Error& e) {
    run.outcome = Outcome::Uncertain;
    run.mode_left_on = e.what();
    run.result->reason += (run.result->reason.empty() ? "" : "; ") + std::string(e.what());
  }
}

// The rules that need no card, for every cell of the profile: read-only, known address,
// range, guard, the card's fixed limits.
void precheck(const profile::Profile& profile, const params::ParamDb& db, const device::WriteOptions& write) {
  for (const auto& s : profile.settings)
    for (const auto& cell : profile::cells_of(profile, s, db))
      device::check_offline(db.get(cell), s.raw, write);
  for (const auto& f : profile::validate_values(profile, db, write.force))
    if (f.severity == profile::Severity::Error)
      throw device::SafetyError(
          (f.key.empty() ? "" : f.key + ": ") + f.message + " [" + f.rule + "]; nothing was written",
          f.advice);
}

}  // namespace

ApplyJob make_apply_job(const ApplyRequest& request) {
  precheck(*request.profile, *request.db, request.write_options());
  ApplyJob job;
  job.profile = request.profile;
  job.db = request.db;
  job.write = request.write_options();
  job.transaction.force = request.force;
  job.transaction.dry_run = request.dry_run;
  job.transaction.reset = request.reset;
  job.transaction.backup_dir = request.backup_dir;
  job.transaction.cancel = request.cancel;
  job.transaction.on_plan = request.on_plan;
  job.open = request.open;
  return job;
}

TargetRun run_apply_on(Amp& amp, const ApplyJob& job, const Activity& activity) {
  TargetRun run;
  run.target = amp.endpoint();
  const auto start = std::chrono::steady_clock::now();
  const auto status_before = sticky_status(amp);
  const std::size_t silences_before = amp.silences_ended();
  auto options = job.transaction;
  options.force = job.write.force;  // one --force: the guards and the rules it overrides
  if (options.backup_label.empty())
    options.backup_label = profile::backup_label(job.profile->name, amp.identity().info.unit_number);
  options.backup_origin = origin_of(amp);
  {
    AmpCellAccess access(amp, job.write, activity);
    run.result = run_transaction(*job.profile, amp.db(), access, options);
    run.refused_by_card = access.refused();
  }
  run.outcome = run.result->outcome;
  if (run.outcome != Outcome::Refused && run.outcome != Outcome::DryRun && run.outcome != Outcome::BadInput &&
      run.outcome != Outcome::Failed) {
    if (activity) activity("checking");
    check_live(amp, job, run);
    check_card_reset(amp, status_before, run);  // last: a reset during the checks is seen too
    check_silent_reset(amp, job, silences_before, run);
    if (!run.card_reset.empty() && run.outcome == Outcome::RolledBack) reload_restored_values(amp, run);
  }
  settle(amp, run);
  run.retries = amp.retries();
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

TargetRun run_apply_opened(const Endpoint& target, const ApplyJob& job, const AmpOpener& open,
                           const Activity& activity) {
  const auto start = std::chrono::steady_clock::now();
  TargetRun run;
  try {
    if (activity) activity("connecting");
    const auto amp = open();
    run = run_apply_on(*amp, job, activity);
  } catch (...) {
    // One meaning for every failure (ops/core/failure.hpp): a defect is uncertain here too.
    const auto failure = failure_of_current_exception();
    run.target = target;
    run.error = failure.line.message;
    run.error_advice = failure.advice;
    run.outcome = failure.outcome;
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (activity) activity("done");
  return run;
}

TargetRun run_apply(const Endpoint& target, const ApplyJob& job, const Activity& activity) {
  return run_apply_opened(
      target, job, [&] { return Amp::open(target, *job.db, job.open, job.transaction.cancel); }, activity);
}

TargetRun run_apply_over(std::unique_ptr<link::Link> link, const Endpoint& target, const ApplyJob& job,
                         const Activity& activity) {
  return run_apply_opened(
      target, job,
      [&] { return Amp::attach(std::move(link), target, *job.db, job.open.retry, job.transaction.cancel); },
      activity);
}

Outcome fleet_outcome(const std::vector<TargetRun>& runs) {
  Outcome worst = Outcome::Done;
  for (const auto& r : runs) worst = most_serious(worst, r.outcome);
  return worst;
}

}  // namespace i20::ops
