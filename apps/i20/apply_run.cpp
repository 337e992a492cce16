#include "apply_run.hpp"

#include <algorithm>
#include <chrono>
#include <exception>

#include "errors.hpp"
#include "faults/bit_info.hpp"
#include "interrupt.hpp"
#include "profile/finding.hpp"

namespace i20::cli {
namespace {

using profile::Outcome;

using faults::kResetCauseBits;
using faults::kStatusExtr;
using faults::kStatusSwr;
using faults::kStatusWdto;

std::optional<std::int64_t> try_read(Connection& c, const std::string& name, unsigned attempts) {
  for (unsigned attempt = 0; attempt < attempts; ++attempt) {
    try {
      return c.amp->read(name).raw;
    } catch (const std::exception&) {
    }
  }
  return std::nullopt;
}

// STATUS, where this firmware's working map is known (reading a wrong address would
// report resets that never happened).
std::optional<std::int64_t> sticky_status(Connection& c) {
  const params::Param* status = c.db.find("STATUS");
  if (!status || !c.db.address_confirmed(*status)) return std::nullopt;
  return try_read(c, "STATUS", 3);
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

// A reset in the middle of an apply reloads every working value from the EEPROM as it was
// then, half written: neither the outcome's "previous values" nor the profile's. Say so.
void check_card_reset(Connection& c, std::optional<std::int64_t> before, TargetRun& run) {
  if (!before) return;
  const auto after = sticky_status(c);
  if (!after) return;
  std::int64_t fresh = *after & ~*before & kResetCauseBits;
  if (run.result->reset_done) fresh &= ~std::int64_t{kStatusSwr};  // ours
  if (fresh == 0) return;
  run.card_reset = "the card reset itself during the apply (STATUS " + reset_names(fresh) +
                   "): its working values were reloaded from the EEPROM as it was at that moment";
}

// NV cells of the profile whose working twin holds something else: not live until a reset.
void check_live(Connection& c, AmpCardAccess& card, const ApplyJob& job, TargetRun& run) {
  const auto& r = *run.result;
  if ((r.outcome != Outcome::Applied && r.outcome != Outcome::NothingToDo) || r.reset_done) return;
  std::vector<std::string> names;
  std::vector<std::pair<std::string, std::string>> pairs;
  try {
    for (const auto& w : profile::cell_writes(*job.profile, c.db)) {
      const params::Param& p = c.db.get(w.cell);
      const params::Param* twin = p.is_nv() && !p.twin.empty() ? c.db.find(p.twin) : nullptr;
      if (!twin || !c.db.address_confirmed(*twin)) continue;
      pairs.emplace_back(p.name, twin->name);
      names.insert(names.end(), {p.name, twin->name});
    }
    if (names.empty()) return;
    const auto values = card.read(names);
    for (const auto& [nv, working] : pairs)
      if (values.at(nv) != values.at(working)) run.not_live.push_back(nv);
  } catch (const std::exception&) {
    // Best effort: the advice below the outcome is then the engine's reset_needed alone.
  }
}

void run_on_card(Connection& c, const TargetSpec& target, const ApplyJob& job, const Activity& activity,
                 TargetRun& run) {
  auto options = job.card;
  options.where = target.text;
  AmpCardAccess card(*c.amp, options, activity);
  const auto status_before = sticky_status(c);
  run.result = profile::apply(*job.profile, c.db, card, job.apply);
  run.refused_by_card = card.refused();
  run.interrupted = card.interrupted();
  if (run.result->outcome != Outcome::Refused && run.result->outcome != Outcome::DryRun) {
    if (activity) activity("checking");
    check_card_reset(c, status_before, run);
    check_live(c, card, job, run);
  }
  run.retries = card.retries();
}

}  // namespace

TargetRun run_apply(const TargetSpec& target, const ApplyJob& job, const Activity& activity) {
  TargetRun run;
  run.target = target.text;
  run.target_flags = command_flags(target);
  const auto start = std::chrono::steady_clock::now();
  try {
    if (activity) activity("connecting");
    // No cancel flag for the card client: see AmpCardAccess::stop_if_interrupted.
    const auto connection = connect(target, *job.db, nullptr, job.card.attempts);
    run_on_card(*connection, target, job, activity, run);
  } catch (const std::exception& e) {
    // Only opening the link or identifying the card throws; apply() never does.
    run.error = e.what();
    run.interrupted = app::interrupted();
  }
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.exit_code = exit_code_of(run);
  if (activity) activity("done");
  return run;
}

int exit_code_of(const TargetRun& run) {
  if (!run.result) return run.interrupted ? app::kInterrupted : app::kFailure;
  const auto& r = *run.result;
  switch (r.outcome) {
    case Outcome::Applied: return r.reset_error.empty() ? app::kOk : app::kCardState;
    case Outcome::NothingToDo:
    case Outcome::DryRun: return app::kOk;
    case Outcome::RolledBack:
    case Outcome::RollbackFailed: return app::kCardState;
    case Outcome::Refused: break;
  }
  if (run.interrupted) return app::kInterrupted;
  if (profile::has_errors(r.findings)) return app::kBadInput;
  if (run.refused_by_card) return app::kRefused;
  return app::kFailure;  // the card could not be read, or the backup not written
}

int fleet_exit_code(const std::vector<TargetRun>& runs) {
  const int rank[] = {app::kCardState, app::kInterrupted, app::kFailure, app::kRefused, app::kBadInput};
  for (const int code : rank)
    if (std::ranges::any_of(runs, [code](const TargetRun& r) { return r.exit_code == code; })) return code;
  for (const auto& r : runs)
    if (r.exit_code != app::kOk) return r.exit_code;
  return app::kOk;
}

bool run_ok(const TargetRun& run) {
  return run.exit_code == app::kOk;
}

}  // namespace i20::cli
