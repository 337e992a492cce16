// SPDX-License-Identifier: GPL-2.0-or-later
#include "soak_common.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "sim/param_map.hpp"

namespace i20::soak {

const char* path_name(Path p) {
  switch (p) {
    case Path::Set: return "set";
    case Path::Wpd: return "wpd";
    case Path::Apply: return "apply";
    case Path::Fleet: return "fleet";
  }
  return "?";
}

// ---------------------------------------------------------------- random consistent targets
Scenario Generator::next() {
  Scenario s;
  s.path = pick<Path>({Path::Set, Path::Wpd, Path::Apply, Path::Fleet});
  s.busv = pick<double>({0, 24, 48, 160, 320});
  targets(s);
  s.injection = serial_injection();
  if (s.path == Path::Fleet) s.injection.heal.reset();  // a fleet opens its own links: no heal clock
  return s;
}

Healing Generator::healing() {
  if (!std::bernoulli_distribution(0.5)(heal_rng_)) return std::nullopt;
  const std::int64_t choices[] = {20, 100, 300, 1000, 1900};
  return std::chrono::milliseconds(choices[std::uniform_int_distribution<std::size_t>(0, 4)(heal_rng_)]);
}

// Thresholds that fit the bus (with margins, so they pass the measured-bus rules), a
// current within 30 A, equal gains: what a careful user would write. One in ten breaks a
// rule on purpose, to see it refused with nothing written.
void Generator::targets(Scenario& s) {
  const std::int64_t bus = static_cast<std::int64_t>(s.busv * 100);
  const std::int64_t on =
      std::min<std::int64_t>(38500, std::max<std::int64_t>(bus + 2000, between(6000, 38500)));
  const std::int64_t off = std::max<std::int64_t>(bus + 500, on - between(1000, 3000));
  const std::int64_t over = std::min<std::int64_t>(40000, on + between(0, 1500));
  const std::int64_t under =
      std::max<std::int64_t>(0, std::min<std::int64_t>(bus - 1000, between(2000, 9000)));
  std::vector<std::pair<std::string, std::int64_t>> pool{{"NVBRAKEONV", on},
                                                         {"NVBRAKEOFFV", off},
                                                         {"NVBUSOVERV", over},
                                                         {"NVBUSUNDERV", under},
                                                         {"NVMAXCURRENT", between(100, 3000)}};
  const std::int64_t kp = between(20, 200);
  pool.insert(pool.end(), {{"NVKQP", kp}, {"NVKDP", kp}});
  if (chance(0.3))
    pool.insert(pool.end(), {{"BRAKEONV", on}, {"BRAKEOFFV", off}, {"MAXCURRENT", between(100, 3000)}});
  std::shuffle(pool.begin(), pool.end(), rng_);
  const std::size_t n =
      s.path == Path::Wpd ? 1 : static_cast<std::size_t>(between(1, static_cast<std::int64_t>(pool.size())));
  s.values.assign(pool.begin(), pool.begin() + static_cast<long>(n));
  if (chance(0.1))
    s.values.front().second = s.values.front().first.find("MAXCURRENT") != std::string::npos ? 4500 : 39000;
  s.both = s.path == Path::Apply && chance(0.3);
  if (s.path == Path::Fleet)
    std::erase_if(s.values, [](const auto& v) { return v.first.rfind("NV", 0) != 0; });
  if (s.values.empty()) s.values.push_back({"NVMAXCURRENT", between(100, 3000)});
}

Injection Generator::serial_injection() {
  Injection i;
  switch (between(0, 7)) {
    case 0: i.label = "none"; break;
    case 1: {
      const double rate = pick<double>({0.001, 0.005, 0.02});
      i.control = {"corrupt " + std::to_string(rate), "seed " + std::to_string(between(1, 1 << 30))};
      i.undo = {"corrupt 0"};
      i.heal = healing();
      i.label = "corrupt " + std::to_string(rate).substr(0, 5);
      break;
    }
    case 2: {
      const double rate = pick<double>({0.01, 0.05});
      i.control = {"drop " + std::to_string(rate), "seed " + std::to_string(between(1, 1 << 30))};
      i.undo = {"drop 0"};
      i.heal = healing();
      i.label = "drop " + std::to_string(rate).substr(0, 4);
      break;
    }
    case 3:
    case 4: {
      const auto n = between(1, 90);
      i.reset_time = std::chrono::milliseconds(between(0, 1));
      i.control = {"reset-after " + std::to_string(n)};
      i.self_heals = true;  // the card answers again after its reset time
      i.label = "reset-after (" + std::to_string(i.reset_time.count()) + " ms)";
      break;
    }
    case 5:
      i.control = {"mute-after " + std::to_string(between(1, 60))};
      i.undo = {"mute-after off"};
      i.heal = healing();
      i.label = "mute-after";
      break;
    case 6: {
      const bool torn = chance(0.5);
      i.control = {std::string("eeprom-power-loss ") + (torn ? "torn" : "lost")};
      i.label = torn ? "power-loss torn" : "power-loss lost";
      break;
    }
    case 7: signal(i); break;
  }
  return i;
}

// What a user, an ssh session that drops or a service manager sends: the handler turns
// each into the same stop request, so only the moment and the repeat vary.
void Generator::signal(Injection& i) {
  i.signal = pick<int>({SIGINT, SIGTERM, SIGHUP});
  i.cancel_after = static_cast<unsigned>(between(0, 30));
  if (chance(0.5)) i.again_after = static_cast<unsigned>(between(0, 20));
  i.label = std::string(i.signal == SIGINT    ? "SIGINT"
                        : i.signal == SIGTERM ? "SIGTERM"
                                              : "SIGHUP") +
            (i.again_after ? " x2" : "");
}

// ---------------------------------------------------------------- the injecting link
void InjectingLink::heal_if_due() {
  if (healed_ || !heal_ || !first_failure_ || !heal_after_) return;
  if (std::chrono::steady_clock::now() < *first_failure_ + *heal_after_) return;
  healed_ = true;
  heal_();
}

void InjectingLink::settle() {
  if (!healed_ && heal_) heal_();
  healed_ = true;
}

bool InjectingLink::healed_within(std::chrono::milliseconds limit) const {
  if (!first_failure_) return false;
  return self_healed_ || (heal_after_ && *heal_after_ <= limit);
}

std::vector<lbp::Bytes> InjectingLink::execute(std::span<const lbp::Command> batch) {
  if (first_ && exchanges_ == *first_) stop_.request(signal_);
  if (first_ && again_ && exchanges_ == *first_ + *again_ + 1) stop_.request(signal_);
  if (action_at_ && exchanges_ == *action_at_ && action_) {
    acted_ = true;
    action_();
  }
  ++exchanges_;
  heal_if_due();
  try {
    return inner_->execute(batch);
  } catch (const link::LinkError&) {
    if (!first_failure_) first_failure_ = std::chrono::steady_clock::now();
    throw;
  }
}

// ---------------------------------------------------------------- the verdict
Verdict verdict(ops::Outcome o) {
  switch (o) {
    case ops::Outcome::Done:
    case ops::Outcome::NothingToDo:
    case ops::Outcome::DryRun: return Verdict::Applied;
    case ops::Outcome::Refused:
    case ops::Outcome::BadInput: return Verdict::Refused;
    case ops::Outcome::Failed:
    case ops::Outcome::OutputLost: return Verdict::NotReached;  // the soak takes no backup: nothing written
    case ops::Outcome::RolledBack:
    case ops::Outcome::Interrupted: return Verdict::RolledBack;
    case ops::Outcome::Uncertain:
    case ops::Outcome::FaultsRemain: return Verdict::Uncertain;
  }
  return Verdict::Uncertain;
}

namespace {
// What each named cell holds, before and after, by the simulator's memory.
std::uint64_t held(const sim::RegisterMap& map, const sim::GroundTruth& t, const std::string& cell) {
  return sim::value_in(t, map.at(cell));
}
}  // namespace

Judged judge(const sim::RegisterMap& map, const sim::GroundTruth& before, const sim::GroundTruth& after,
             const ops::TargetRun& run, const Wanted& wanted) {
  Judged j;
  std::vector<std::string> named;
  for (const auto& [cell, raw] : wanted) named.push_back(cell);
  j.stray = sim::unexplained_changes(map, before, after, named);
  for (const auto& c : sim::crossed_thresholds(map, after)) {
    const auto already = sim::crossed_thresholds(map, before);
    if (std::find(already.begin(), already.end(), c) == already.end()) j.crossed.push_back(c);
  }
  j.modes_on = after.nv_access != lbp::local::NvAccess::Ram || after.rpcmem;
  // A working cell the card reloaded at a reset is not the tool's doing when the tool said
  // the card reset, or when the reset came after the reply to its last command (the host
  // sent nothing after it: no tool can see that, as with a reset a second later).
  const bool said_reset = !run.card_reset.empty() || (run.result && !run.result->events.empty());
  const bool reset = after.resets != before.resets;
  // Called only for a cell that would otherwise be a finding.
  const auto reloaded = [&](const std::string& cell) {
    const bool excused = map.at(cell).space == sim::Space::Ram && reset &&
                         (said_reset || after.quiet_since_reset) &&
                         sim::reloaded_by_reset(map, map.at(cell), after);
    if (excused && !said_reset) j.unseen_reset = true;
    return excused;
  };
  const auto changed = [&](const std::string& cell) {
    return held(map, before, cell) != held(map, after, cell);
  };
  switch (verdict(run.outcome)) {
    case Verdict::Applied:
      for (const auto& [cell, raw] : wanted)
        if (held(map, after, cell) != static_cast<std::uint64_t>(raw) && !reloaded(cell))
          j.wrong.push_back(std::string("verified, yet ") + cell + " holds " +
                            std::to_string(held(map, after, cell)) + " instead of " + std::to_string(raw));
      break;
    case Verdict::Refused:
    case Verdict::NotReached:
      for (const auto& cell : named)
        if (changed(cell) && !reloaded(cell))
          j.wrong.push_back(std::string("nothing written, yet ") + cell + " changed");
      break;
    case Verdict::RolledBack:
      for (const auto& cell : named)
        if (changed(cell) && !reloaded(cell))
          j.wrong.push_back(std::string("restored, yet ") + cell + " holds " +
                            std::to_string(held(map, after, cell)));
      break;
    case Verdict::Uncertain: {
      // Every cell that may differ must be named, and what the report says a cell holds
      // must be what it holds.
      const auto& cells = run.result ? run.result->cells : std::vector<ops::CellState>{};
      for (const auto& cell : named) {
        const auto it =
            std::find_if(cells.begin(), cells.end(), [&](const ops::CellState& c) { return c.cell == cell; });
        if (changed(cell) && it == cells.end() && !reloaded(cell))
          j.wrong.push_back("uncertain, but " + cell + " changed and is not named");
        if (it != cells.end() && it->actual && after.powered &&
            static_cast<std::uint64_t>(*it->actual) != held(map, after, cell) &&
            !(after.quiet_since_reset && reloaded(cell)))
          j.wrong.push_back("uncertain, and " + cell + " reported as " + std::to_string(*it->actual) +
                            " holds " + std::to_string(held(map, after, cell)));
      }
      break;
    }
  }
  return j;
}

// ---------------------------------------------------------------- running one scenario
profile::Profile profile_of(const Scenario& s, const params::ParamDb& db) {
  profile::Profile p;
  p.source = "soak";
  p.name = "soak";
  for (const auto& [cell, raw] : s.values) {
    profile::Setting setting;
    setting.name = db.get(cell).name;
    setting.raw = raw;
    if (s.both && db.get(cell).is_nv() && !db.get(cell).twin.empty()) setting.target = profile::Memory::Both;
    p.settings.push_back(setting);
  }
  return p;
}

Wanted cells_written(const Scenario& s, const params::ParamDb& db) {
  auto out = s.values;
  if (s.both)
    for (const auto& [cell, raw] : s.values)
      if (db.get(cell).is_nv() && !db.get(cell).twin.empty()) out.push_back({db.get(cell).twin, raw});
  return out;
}

namespace {

// Why a run ended as it did, for --verbose: the error that kept the card from being
// reached, or the transaction's reason and the mode it may have left on.
std::string why(const ops::TargetRun& run) {
  std::string text = run.error;
  if (run.result && !run.result->reason.empty())
    text.append(text.empty() ? "" : "; ").append(run.result->reason);
  if (!run.mode_left_on.empty() && text.find(run.mode_left_on) == std::string::npos)
    text.append(text.empty() ? "" : "; ").append(run.mode_left_on);
  return text.empty() ? std::string() : std::string(" (").append(text).append(")");
}

}  // namespace

void record(Tally& t, const Scenario& s, std::size_t index, const ops::TargetRun& run, const Judged& j,
            bool verbose, std::optional<bool> healed) {
  ++t.outcomes[verdict(run.outcome)];
  const bool exit0 = run.exit_code() == 0;
  if (!j.wrong.empty()) ++t.silently_wrong;
  if (!j.stray.empty()) ++t.stray;
  if (!j.crossed.empty()) ++t.crossed;
  if (j.modes_on) ++t.modes_on;
  if (j.unseen_reset) ++t.unseen_resets;
  if (j.modes_on && exit0) ++t.modes_on_exit0;
  // Exit 130 promises a card left in a known state: modes off, what was written restored.
  if (j.modes_on && run.exit_code() == ops::kExitInterrupted) ++t.modes_on_exit130;
  if (s.injection.cancel_after) ++t.signalled;
  if (run.outcome == ops::Outcome::Interrupted) ++t.stopped;
  if (healed) {
    ++t.failed_links;
    if (*healed) {
      ++t.healed;
      if (verdict(run.outcome) == Verdict::Uncertain) ++t.healed_uncertain;
    }
  }
  const std::string label =
      s.injection.label +
      (s.injection.heal ? " healed " + std::to_string(s.injection.heal->count()) + " ms" : "");
  std::vector<std::string> all = j.wrong;
  all.insert(all.end(), j.stray.begin(), j.stray.end());
  all.insert(all.end(), j.crossed.begin(), j.crossed.end());
  all.insert(all.end(), j.other.begin(), j.other.end());
  if (j.modes_on && exit0) all.push_back("NV or RPC memory mode left on with exit 0");
  if (j.modes_on && run.exit_code() == ops::kExitInterrupted)
    all.push_back("NV or RPC memory mode left on with exit 130");
  for (const auto& f : all) {
    // append(), not operator+: GCC 12 -O3 warns -Wrestrict inside operator+ (a false positive).
    std::string finding = "#";
    finding.append(std::to_string(index)).append(" ").append(path_name(s.path)).append(" / ").append(label);
    finding.append(" -> ").append(ops::to_string(run.outcome)).append(": ").append(f);
    t.findings.push_back(std::move(finding));
  }
  if (verbose)
    std::cerr << "#" << index << " " << path_name(s.path) << " " << s.values.size() << " cells, " << label
              << " -> " << ops::to_string(run.outcome) << why(run) << (all.empty() ? "" : "  FINDING")
              << "\n";
}

std::vector<ops::TargetRun> fleet_runs(const std::vector<ops::Endpoint>& targets,
                                       const ops::ApplyRequest& request) {
  try {
    return ops::run_fleet(targets, ops::make_apply_job(request));
  } catch (const Error& e) {
    std::vector<ops::TargetRun> refused(targets.size());
    for (std::size_t i = 0; i < targets.size(); ++i) {
      refused[i].target = targets[i];
      refused[i].outcome = ops::outcome_of(e.kind());
      refused[i].error = e.what();
    }
    return refused;
  }
}

ops::ApplyRequest request_for(const profile::Profile& p, const params::ParamDb& db, const ops::Cancel& cancel,
                              const std::filesystem::path& backups, Path path, unsigned timeout_ms) {
  ops::ApplyRequest request{.profile = &p, .db = &db, .cancel = cancel};
  if (path == Path::Apply || path == Path::Fleet) request.backup_dir = backups;
  request.open.link.timeout_ms = timeout_ms;
  return request;
}

bool clean(const Tally& t) {
  return t.silently_wrong == 0 && t.stray == 0 && t.crossed == 0 && t.modes_on_exit0 == 0 &&
         t.modes_on_exit130 == 0 && t.host_disturbed == 0 && t.port_stuck == 0;
}

void print(const Tally& t, std::size_t n, std::uint64_t seed, double seconds, const std::string& what,
           const std::string& runs_note, bool eth) {
  const auto count = [&](Verdict v) { return t.outcomes.count(v) ? t.outcomes.at(v) : 0; };
  std::printf("i20-soak: %zu scenarios, seed %llu, %.1f s, path: %s (simulated, not hardware)\n", n,
              static_cast<unsigned long long>(seed), seconds, what.c_str());
  std::printf("  card runs judged                 %zu (%s)\n", t.scenarios, runs_note.c_str());
  std::printf("  applied and verified             %zu\n", count(Verdict::Applied));
  std::printf("  refused (nothing written)        %zu\n", count(Verdict::Refused));
  std::printf("  not reached (nothing written)    %zu\n", count(Verdict::NotReached));
  std::printf("  rolled back (or signal restored) %zu\n", count(Verdict::RolledBack));
  std::printf("  uncertain, and said so           %zu\n", count(Verdict::Uncertain));
  std::printf("  must be 0:\n");
  std::printf("    silently wrong                 %zu\n", t.silently_wrong);
  std::printf("    stray writes                   %zu\n", t.stray);
  std::printf("    unsafe states left             %zu\n", t.crossed);
  std::printf("    modes left on with exit 0      %zu\n", t.modes_on_exit0);
  std::printf("    modes left on with exit 130    %zu\n", t.modes_on_exit130);
  if (eth) {
    std::printf("    running host disturbed         %zu (of %zu runs with a host started mid-run)\n",
                t.host_disturbed, t.host_runs);
    std::printf("    SSERIAL port left stuck        %zu (held in reset, or COMMAND busy after the run)\n",
                t.port_stuck);
  }
  std::printf("  (modes left on after a card went silent or dead, reported uncertain: %zu)\n", t.modes_on);
  std::printf("  (reset right after the tool's last reply, unseeable, working values reloaded: %zu)\n",
              t.unseen_resets);
  std::printf(
      "  (card runs sent SIGINT/SIGTERM/SIGHUP, once or twice: %zu; of them stopped, exit 130: %zu)\n",
      t.signalled, t.stopped);
  std::printf(
      "  (link failed in %zu card runs; it healed within 2 s in %zu; of those uncertain: %zu = %.0f%%)\n",
      t.failed_links, t.healed, t.healed_uncertain,
      t.healed ? 100.0 * static_cast<double>(t.healed_uncertain) / static_cast<double>(t.healed) : 0.0);
  if (!t.port_left.empty()) {
    std::printf("  (SSERIAL channels after the run:");
    for (const auto& [mode, c] : t.port_left) std::printf(" %s %zu", mode.c_str(), c);
    std::printf(")\n");
  }
  for (std::size_t i = 0; i < t.findings.size() && i < 30; ++i)
    std::printf("  FINDING %s\n", t.findings[i].c_str());
}

}  // namespace i20::soak
