// SPDX-License-Identifier: GPL-2.0-or-later
// What both soaks share (tools/soak.cpp over the in-process serial simulator,
// tools/soak_eth.cpp over the virtual Ethernet cards): the random scenarios, the signal
// and heal injections counted in link exchanges, the judge that compares the report with
// the simulator's memory, the tally and its table. Everything runs against simulators.
#pragma once

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "link/link.hpp"
#include "ops/apply_run.hpp"
#include "ops/core/cancel.hpp"
#include "ops/fleet.hpp"
#include "params/param_db.hpp"
#include "profile/profile.hpp"
#include "sim/ground_truth.hpp"
#include "sim/register_map.hpp"

namespace i20::soak {

enum class Path { Set, Wpd, Apply, Fleet };
const char* path_name(Path p);

// The link stops answering (or answers badly) for a while, then heals: drawn for the
// injections that can end (drops, corruption, a mute, a lossy network, a dark card).
using Healing = std::optional<std::chrono::milliseconds>;  // nullopt: lasts to the end of the run

// One injection, as the simulator's control language says it ("corrupt 0.01"), or a stop
// request (SIGINT, SIGTERM or SIGHUP, once or twice) after a number of exchanges: not a
// control line but the tool's input, set as the apps' signal handler sets it.
struct Injection {
  std::vector<std::string> control;  // applied once the card is open
  std::vector<std::string> undo;     // what ends it (the heal); empty: the soak's end-of-run reset
  std::optional<unsigned> cancel_after;
  std::optional<unsigned> again_after;  // the second signal, this many exchanges after the first
  int signal = SIGINT;
  std::chrono::milliseconds reset_time{1};
  Healing heal;             // heal this long after the first failed exchange
  bool self_heals = false;  // the card answers again by itself (a reset)
  std::string label;
};

struct Scenario {
  Path path = Path::Set;
  double busv = 320;
  std::vector<std::pair<std::string, std::int64_t>> values;  // cell -> raw, in the order given
  bool both = false;                                         // apply: NV cells with their working twins
  Injection injection;
};

// Random consistent targets and one serial-side injection per scenario. The heal draws come
// from a second stream, so the scenarios of a seed are the same with or without them.
class Generator {
 public:
  explicit Generator(std::uint64_t seed) : rng_(seed), heal_rng_(seed ^ 0x5EA1ull) {}

  Scenario next();
  // One injection the serial soak knows (also what the Ethernet soak injects behind the
  // passthrough).
  Injection serial_injection();

  template <class T>
  T pick(std::initializer_list<T> items) {
    std::uniform_int_distribution<std::size_t> d(0, items.size() - 1);
    return *(items.begin() + d(rng_));
  }
  std::int64_t between(std::int64_t lo, std::int64_t hi) {
    return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng_);
  }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }
  // Half the healable injections end after 20 ms .. 1.9 s, the rest last the run.
  Healing healing();

 private:
  void targets(Scenario& s);
  void signal(Injection& i);

  std::mt19937_64 rng_;
  std::mt19937_64 heal_rng_;
};

// A link that counts exchanges: the stop request arrives before exchange K (again K2 later),
// `at(K, action)` runs an action before exchange K (a card reset, a host starting), and the
// first failed exchange starts the heal clock; the heal runs before the first exchange
// after it is due, or at the end of the run (settle()).
class InjectingLink final : public link::Link {
 public:
  InjectingLink(std::unique_ptr<link::Link> inner, ops::StopRequest& stop)
      : inner_(std::move(inner)), stop_(stop) {}
  void arm_signal(const Injection& i) {
    first_ = i.cancel_after, again_ = i.again_after, signal_ = i.signal, exchanges_ = 0;
  }
  void at(unsigned exchange, std::function<void()> action) {
    action_at_ = exchanges_ + exchange, action_ = std::move(action);
  }
  void heal_with(std::chrono::milliseconds after, std::function<void()> heal) {
    heal_after_ = after, heal_ = std::move(heal);
  }
  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override;
  std::string describe() const override { return inner_->describe(); }
  std::size_t max_data_bytes() const override { return inner_->max_data_bytes(); }
  std::vector<std::string> notes() const override { return inner_->notes(); }

  // Runs a heal still pending (the run is over: the fault ends now at the latest).
  void settle();
  bool failed() const { return first_failure_.has_value(); }
  bool acted() const { return acted_; }  // the at() action ran (the run got that far)
  // The link failed and the fault ended (or was due to end) within `limit` of that.
  bool healed_within(std::chrono::milliseconds limit) const;
  // The first failure, for an injection that ends by itself (a reset, a card that comes back).
  void self_healed() { self_healed_ = true; }

 private:
  void heal_if_due();

  std::unique_ptr<link::Link> inner_;
  ops::StopRequest& stop_;
  std::optional<unsigned> first_, again_;
  int signal_ = SIGINT;
  unsigned exchanges_ = 0;
  std::optional<unsigned> action_at_;
  std::function<void()> action_;
  std::optional<std::chrono::milliseconds> heal_after_;
  std::function<void()> heal_;
  bool healed_ = false, self_healed_ = false, acted_ = false;
  std::optional<std::chrono::steady_clock::time_point> first_failure_;
};

// ---------------------------------------------------------------- the verdict
enum class Verdict { Applied, Refused, NotReached, RolledBack, Uncertain };
Verdict verdict(ops::Outcome o);

struct Tally {
  std::map<Verdict, std::size_t> outcomes;
  std::size_t scenarios = 0, silently_wrong = 0, stray = 0, crossed = 0, modes_on_exit0 = 0, modes_on = 0,
              unseen_resets = 0, signalled = 0, stopped = 0, modes_on_exit130 = 0;
  // Ethernet only: a host running the machine found stopped or failing after the run, and
  // a port left held in reset or busy.
  std::size_t host_disturbed = 0, port_stuck = 0, host_runs = 0;
  // Issue 18 item 3: runs whose link failed and healed within 2 s, and of them uncertain.
  std::size_t healed = 0, healed_uncertain = 0, failed_links = 0;
  std::map<std::string, std::size_t> port_left;  // SSERIAL channel modes after the run
  std::vector<std::string> findings;
};

struct Judged {
  std::vector<std::string> wrong;  // the report contradicts the card
  std::vector<std::string> stray;
  std::vector<std::string> crossed;
  std::vector<std::string> other;  // Ethernet: a disturbed host, a stuck port
  bool modes_on = false;
  bool unseen_reset = false;  // a cell was excused by a reset after the tool's last reply
};

using Wanted = std::vector<std::pair<std::string, std::int64_t>>;
Judged judge(const sim::RegisterMap& map, const sim::GroundTruth& before, const sim::GroundTruth& after,
             const ops::TargetRun& run, const Wanted& wanted);

profile::Profile profile_of(const Scenario& s, const params::ParamDb& db);
Wanted cells_written(const Scenario& s, const params::ParamDb& db);
// The fleet as `i20 profile apply` runs it: a request the rules that need no card refuse
// (make_apply_job throws) is refused for every target with nothing opened.
std::vector<ops::TargetRun> fleet_runs(const std::vector<ops::Endpoint>& targets,
                                       const ops::ApplyRequest& request);

ops::ApplyRequest request_for(const profile::Profile& p, const params::ParamDb& db, const ops::Cancel& cancel,
                              const std::filesystem::path& backups, Path path, unsigned timeout_ms);

// Counts the run in the tally; `healed`: the link failed and healed within 2 s.
void record(Tally& t, const Scenario& s, std::size_t index, const ops::TargetRun& run, const Judged& j,
            bool verbose, std::optional<bool> healed = std::nullopt);

// The table; `what` names the path ("serial, in-process virtual 8I20").
void print(const Tally& t, std::size_t n, std::uint64_t seed, double seconds, const std::string& what,
           const std::string& runs_note, bool eth);
bool clean(const Tally& t);

}  // namespace i20::soak
