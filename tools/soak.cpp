// SPDX-License-Identifier: GPL-2.0-or-later
// i20-soak N SEED: N random write scenarios against the in-process virtual 8I20, each with
// one injected fault, every one judged by the simulator's own memory (EEPROM image, RAM,
// NV access and RPC memory flags), never by what the tool reports. Prints one table; the
// columns under "must be 0" are defects when they are not. Exit 1 if any of them is not 0.
//
// Everything here runs against the simulator, not hardware.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "link/pipelined_link.hpp"
#include "ops/apply_run.hpp"
#include "ops/change.hpp"
#include "ops/fleet.hpp"
#include "params/value.hpp"
#include "sim/ground_truth.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"

using namespace i20;
namespace fs = std::filesystem;

namespace {

enum class Path { Set, Wpd, Apply, Fleet };
const char* path_name(Path p) {
  switch (p) {
    case Path::Set: return "set";
    case Path::Wpd: return "wpd";
    case Path::Apply: return "apply";
    case Path::Fleet: return "fleet";
  }
  return "?";
}

// One injection, as the simulator's control language says it ("corrupt 0.01"), or a stop
// request (SIGINT, SIGTERM or SIGHUP, once or twice) after a number of exchanges: not a
// control line but the tool's input, set as the apps' signal handler sets it.
struct Injection {
  std::vector<std::string> control;  // applied once the card is open
  std::optional<unsigned> cancel_after;
  std::optional<unsigned> again_after;  // the second signal, this many exchanges after the first
  int signal = SIGINT;
  std::chrono::milliseconds reset_time{1};
  std::string label;
};

struct Scenario {
  Path path = Path::Set;
  double busv = 320;
  std::vector<std::pair<std::string, std::int64_t>> values;  // cell -> raw, in the order given
  bool both = false;                                         // apply: NV cells with their working twins
  Injection injection;
};

// ---------------------------------------------------------------- random consistent targets
class Generator {
 public:
  explicit Generator(std::uint64_t seed) : rng_(seed) {}

  Scenario next() {
    Scenario s;
    s.path = pick<Path>({Path::Set, Path::Wpd, Path::Apply, Path::Fleet});
    s.busv = pick<double>({0, 24, 48, 160, 320});
    targets(s);
    s.injection = injection();
    return s;
  }

 private:
  template <class T>
  T pick(std::initializer_list<T> items) {
    std::uniform_int_distribution<std::size_t> d(0, items.size() - 1);
    return *(items.begin() + d(rng_));
  }
  std::int64_t between(std::int64_t lo, std::int64_t hi) {
    return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng_);
  }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }

  // Thresholds that fit the bus (with margins, so they pass the measured-bus rules), a
  // current within 30 A, equal gains: what a careful user would write. One in ten breaks a
  // rule on purpose, to see it refused with nothing written.
  void targets(Scenario& s) {
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
    const std::size_t n = s.path == Path::Wpd
                              ? 1
                              : static_cast<std::size_t>(between(1, static_cast<std::int64_t>(pool.size())));
    s.values.assign(pool.begin(), pool.begin() + static_cast<long>(n));
    if (chance(0.1))
      s.values.front().second = s.values.front().first.find("MAXCURRENT") != std::string::npos ? 4500 : 39000;
    s.both = s.path == Path::Apply && chance(0.3);
    if (s.path == Path::Fleet)
      std::erase_if(s.values, [](const auto& v) { return v.first.rfind("NV", 0) != 0; });
    if (s.values.empty()) s.values.push_back({"NVMAXCURRENT", between(100, 3000)});
  }

  Injection injection() {
    Injection i;
    switch (between(0, 7)) {
      case 0: i.label = "none"; break;
      case 1: {
        const double rate = pick<double>({0.001, 0.005, 0.02});
        i.control = {"corrupt " + std::to_string(rate), "seed " + std::to_string(between(1, 1 << 30))};
        i.label = "corrupt " + std::to_string(rate).substr(0, 5);
        break;
      }
      case 2: {
        const double rate = pick<double>({0.01, 0.05});
        i.control = {"drop " + std::to_string(rate), "seed " + std::to_string(between(1, 1 << 30))};
        i.label = "drop " + std::to_string(rate).substr(0, 4);
        break;
      }
      case 3:
      case 4: {
        const auto n = between(1, 90);
        i.reset_time = std::chrono::milliseconds(between(0, 1));
        i.control = {"reset-after " + std::to_string(n)};
        i.label = "reset-after (" + std::to_string(i.reset_time.count()) + " ms)";
        break;
      }
      case 5: i.control = {"mute-after " + std::to_string(between(1, 60))}, i.label = "mute-after"; break;
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
  void signal(Injection& i) {
    i.signal = pick<int>({SIGINT, SIGTERM, SIGHUP});
    i.cancel_after = static_cast<unsigned>(between(0, 30));
    if (chance(0.5)) i.again_after = static_cast<unsigned>(between(0, 20));
    i.label = std::string(i.signal == SIGINT    ? "SIGINT"
                          : i.signal == SIGTERM ? "SIGTERM"
                                                : "SIGHUP") +
              (i.again_after ? " x2" : "");
  }

  std::mt19937_64 rng_;
};

// ---------------------------------------------------------------- a signal after K exchanges
class CancellingLink final : public link::Link {
 public:
  CancellingLink(std::unique_ptr<link::Link> inner, ops::StopRequest& stop)
      : inner_(std::move(inner)), stop_(stop) {}
  // From now on, the signal "arrives" just before the exchange after `exchanges` more, and
  // again `again` exchanges later when it is sent twice.
  void arm(const Injection& i) {
    first_ = i.cancel_after, again_ = i.again_after, signal_ = i.signal, exchanges_ = 0;
  }
  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override {
    if (first_ && exchanges_ == *first_) stop_.request(signal_);
    if (first_ && again_ && exchanges_ == *first_ + *again_ + 1) stop_.request(signal_);
    ++exchanges_;
    return inner_->execute(batch);
  }
  std::string describe() const override { return inner_->describe(); }

 private:
  std::unique_ptr<link::Link> inner_;
  ops::StopRequest& stop_;
  std::optional<unsigned> first_, again_;
  int signal_ = SIGINT;
  unsigned exchanges_ = 0;
};

// ---------------------------------------------------------------- the verdict
enum class Verdict { Applied, Refused, NotReached, RolledBack, Uncertain };
struct Tally {
  std::map<Verdict, std::size_t> outcomes;
  std::size_t scenarios = 0, silently_wrong = 0, stray = 0, crossed = 0, modes_on_exit0 = 0, modes_on = 0,
              unseen_resets = 0, signalled = 0, stopped = 0, modes_on_exit130 = 0;
  std::vector<std::string> findings;
};

Verdict verdict(ops::Outcome o) {
  switch (o) {
    case ops::Outcome::Done:
    case ops::Outcome::NothingToDo:
    case ops::Outcome::DryRun: return Verdict::Applied;
    case ops::Outcome::Refused:
    case ops::Outcome::BadInput: return Verdict::Refused;
    case ops::Outcome::Failed: return Verdict::NotReached;
    case ops::Outcome::RolledBack:
    case ops::Outcome::Interrupted: return Verdict::RolledBack;
    case ops::Outcome::Uncertain:
    case ops::Outcome::FaultsRemain: return Verdict::Uncertain;
  }
  return Verdict::Uncertain;
}

struct Judged {
  std::vector<std::string> wrong;  // the report contradicts the card
  std::vector<std::string> stray;
  std::vector<std::string> crossed;
  bool modes_on = false;
  bool unseen_reset = false;  // a cell was excused by a reset after the tool's last reply
};

// What each named cell holds, before and after, by the simulator's memory.
std::uint64_t held(const sim::RegisterMap& map, const sim::GroundTruth& t, const std::string& cell) {
  return sim::value_in(t, map.at(cell));
}

Judged judge(const sim::RegisterMap& map, const sim::GroundTruth& before, const sim::GroundTruth& after,
             const ops::TargetRun& run, const std::vector<std::pair<std::string, std::int64_t>>& wanted) {
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
    if (s.both && db.get(cell).is_nv() && !db.get(cell).twin.empty()) setting.target = profile::Target::Both;
    p.settings.push_back(setting);
  }
  return p;
}

std::vector<std::pair<std::string, std::int64_t>> cells_written(const Scenario& s,
                                                                const params::ParamDb& db) {
  auto out = s.values;
  if (s.both)
    for (const auto& [cell, raw] : s.values)
      if (db.get(cell).is_nv() && !db.get(cell).twin.empty()) out.push_back({db.get(cell).twin, raw});
  return out;
}

void record(Tally& t, const Scenario& s, std::size_t index, const ops::TargetRun& run, const Judged& j,
            bool verbose) {
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
  std::vector<std::string> all = j.wrong;
  all.insert(all.end(), j.stray.begin(), j.stray.end());
  all.insert(all.end(), j.crossed.begin(), j.crossed.end());
  if (j.modes_on && exit0) all.push_back("NV or RPC memory mode left on with exit 0");
  if (j.modes_on && run.exit_code() == ops::kExitInterrupted)
    all.push_back("NV or RPC memory mode left on with exit 130");
  for (const auto& f : all)
    t.findings.push_back("#" + std::to_string(index) + " " + path_name(s.path) + " / " + s.injection.label +
                         " -> " + ops::to_string(run.outcome) + ": " + f);
  if (verbose)
    std::cerr << "#" << index << " " << path_name(s.path) << " " << s.values.size() << " cells, "
              << s.injection.label << " -> " << ops::to_string(run.outcome)
              << (all.empty() ? "" : "  FINDING") << "\n";
}

ops::ApplyJob job_for(const profile::Profile& p, const params::ParamDb& db, const ops::Cancel& cancel,
                      const fs::path& backups, Path path) {
  ops::ApplyJob job;
  job.profile = &p;
  job.db = &db;
  job.transaction.cancel = cancel;
  if (path == Path::Apply || path == Path::Fleet) job.transaction.backup_dir = backups;
  job.open.link.timeout_ms = 5;
  return job;
}

void run_single(const Scenario& s, std::size_t index, const params::ParamDb& db, const fs::path& dir,
                Tally& t, bool verbose, bool trace) {
  sim::SimOptions options;
  options.device.map = sim::register_map_from(db);
  options.device.reset_time = s.injection.reset_time;
  options.device.world.bus_volts = s.busv;
  auto stream = std::make_unique<sim::SimStream>(std::move(options));
  sim::SimStream& sim = *stream;
  link::PipelinedLinkOptions link_options;
  link_options.base_timeout = std::chrono::milliseconds(5);
  ops::StopRequest stop;
  const ops::Cancel cancel(stop, [](const std::string&) {});  // the apps print the acknowledgement
  const auto map = sim.with_card([](sim::Virtual8i20& c) { return c.amplifier().map(); });
  const auto profile = profile_of(s, db);
  const auto job = job_for(profile, db, cancel, dir, s.path);
  auto link = std::make_unique<CancellingLink>(
      std::make_unique<link::PipelinedLink>(std::move(stream), link_options), stop);
  CancellingLink& signals = *link;
  std::unique_ptr<ops::Card> card;
  try {
    card = ops::Card::attach(std::move(link), ops::parse_endpoint("sim"), db, {}, cancel);
  } catch (const Error& e) {
    t.findings.push_back("#" + std::to_string(index) +
                         ": the card could not be opened without a fault: " + e.what());
    return;
  }
  const auto before = sim.with_card([](sim::Virtual8i20& c) { return sim::capture(c); });
  if (trace)
    sim.with_card([index](sim::Virtual8i20& c) {
      c.set_trace(
          [index](const std::string& line) { std::cerr << "  #" << index << " card: " << line << "\n"; });
      return 0;
    });
  for (const auto& line : s.injection.control) sim.control(line);
  if (s.injection.cancel_after) signals.arm(s.injection);  // counted from here
  ops::TargetRun run;
  try {
    ops::precheck(profile, card->db(), job.write);
    run = ops::run_apply_on(*card, job);
  } catch (const Error& e) {
    run.outcome = ops::outcome_of(e.kind());
    run.error = e.what();
  }
  for (const char* off :
       {"corrupt 0", "drop 0", "reset-after off", "mute-after off", "eeprom-power-loss off"})
    sim.control(off);
  const auto after = sim.with_card([](sim::Virtual8i20& c) { return sim::capture(c); });
  record(t, s, index, run, judge(map, before, after, run, cells_written(s, db)), verbose);
}

// Three in-process simulators with their EEPROMs in files, the injection given to all of
// them as control lines; judged by the EEPROM images left on disk.
void run_fleet(const Scenario& s, std::size_t index, const params::ParamDb& db, const fs::path& dir, Tally& t,
               bool verbose) {
  const auto map = sim::register_map_from(db);
  std::vector<ops::Endpoint> targets;
  std::vector<sim::GroundTruth> before;
  for (int i = 0; i < 3; ++i) {
    const auto image = dir / ("card" + std::to_string(i) + ".eeprom");
    fs::remove(image);
    { sim::EepromStore(map, sim::kDefaultEepromBytes, image); }
    sim::GroundTruth g;
    std::ifstream in(image, std::ios::binary);
    g.eeprom.assign(std::istreambuf_iterator<char>(in), {});
    g.ram.assign(0x10000, 0);
    before.push_back(g);
    targets.push_back(ops::parse_endpoint("sim:" + image.string(), static_cast<std::size_t>(i)));
  }
  ops::StopRequest stop;
  const auto profile = profile_of(s, db);
  auto job = job_for(profile, db, ops::Cancel(stop, [](const std::string&) {}), dir, s.path);
  job.open.link.sim_control = {"busv " + std::to_string(s.busv)};
  job.open.link.sim_control.insert(job.open.link.sim_control.end(), s.injection.control.begin(),
                                   s.injection.control.end());
  // A signal after a while (the one scenario kind whose timing is not fixed by the seed).
  std::thread signals;
  if (s.injection.cancel_after)
    signals = std::thread([&stop, i = s.injection] {
      std::this_thread::sleep_for(std::chrono::microseconds(500 * *i.cancel_after));
      stop.request(i.signal);
      if (!i.again_after) return;
      std::this_thread::sleep_for(std::chrono::microseconds(500 * *i.again_after));
      stop.request(i.signal);
    });
  const auto runs = ops::run_fleet(targets, job);
  if (signals.joinable()) signals.join();
  for (std::size_t i = 0; i < runs.size(); ++i) {
    sim::GroundTruth after = before[i];
    std::ifstream in(dir / ("card" + std::to_string(i) + ".eeprom"), std::ios::binary);
    after.eeprom.assign(std::istreambuf_iterator<char>(in), {});
    std::vector<std::pair<std::string, std::int64_t>> nv;
    for (const auto& v : s.values) nv.push_back(v);
    auto j = judge(map, before[i], after, runs[i], nv);
    j.modes_on = false;  // the process-local card is gone: only its EEPROM can be judged
    std::erase_if(j.crossed, [](const std::string& c) { return c.rfind("NV", 0) != 0; });
    record(t, s, index, runs[i], j, verbose);
  }
}

void print(const Tally& t, std::size_t n, std::uint64_t seed, double seconds) {
  const auto count = [&](Verdict v) { return t.outcomes.count(v) ? t.outcomes.at(v) : 0; };
  std::printf(
      "i20-soak: %zu scenarios, seed %llu, %.1f s (in-process virtual 8I20; simulated, not hardware)\n", n,
      static_cast<unsigned long long>(seed), seconds);
  std::printf("  card runs judged                 %zu (a fleet scenario is three cards)\n", t.scenarios);
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
  std::printf("  (modes left on after a card went silent or dead, reported uncertain: %zu)\n", t.modes_on);
  std::printf("  (reset right after the tool's last reply, unseeable, working values reloaded: %zu)\n",
              t.unseen_resets);
  std::printf(
      "  (card runs sent SIGINT/SIGTERM/SIGHUP, once or twice: %zu; of them stopped, exit 130: %zu)\n",
      t.signalled, t.stopped);
  for (std::size_t i = 0; i < t.findings.size() && i < 30; ++i)
    std::printf("  FINDING %s\n", t.findings[i].c_str());
}

}  // namespace

int main(int argc, char** argv) {
  const auto usage = [] {
    std::cerr << "usage: i20-soak N SEED [--verbose] [--trace] [--only K]...\n"
                 "  N random write scenarios against the simulator; --only K runs just scenario K of them\n"
                 "  (the same scenario as in the full run: the generator still draws all N);\n"
                 "  --trace prints every command the virtual card executes (single-card scenarios)\n";
    return 2;
  };
  if (argc < 3) return usage();
  std::size_t n = 0;
  std::uint64_t seed = 0;
  bool verbose = false, trace = false;
  std::vector<std::size_t> only;
  try {
    n = std::stoul(argv[1]);
    seed = std::stoull(argv[2]);
    for (int a = 3; a < argc; ++a) {
      const std::string arg = argv[a];
      if (arg == "--verbose")
        verbose = true;
      else if (arg == "--trace")
        trace = verbose = true;
      else if (arg == "--only" && a + 1 < argc)
        only.push_back(std::stoul(argv[++a]));
      else
        return usage();
    }
  } catch (const std::exception&) {
    return usage();
  }
  const auto db = params::ParamDb::builtin();
  const auto dir = fs::temp_directory_path() / ("i20-soak-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Generator gen(seed);
  Tally tally;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < n; ++i) {
    const Scenario s = gen.next();
    if (!only.empty() && std::find(only.begin(), only.end(), i) == only.end()) continue;
    if (s.path == Path::Fleet)
      run_fleet(s, i, db, dir, tally, verbose);
    else
      run_single(s, i, db, dir, tally, verbose, trace);
  }
  for (const auto& [v, c] : tally.outcomes) tally.scenarios += c;
  fs::remove_all(dir);
  print(tally, only.empty() ? n : only.size(), seed,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  const bool clean = tally.silently_wrong == 0 && tally.stray == 0 && tally.crossed == 0 &&
                     tally.modes_on_exit0 == 0 && tally.modes_on_exit130 == 0;
  return clean ? 0 : 1;
}
