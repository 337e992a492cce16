// SPDX-License-Identifier: GPL-2.0-or-later
// An in-memory 8I20 for apply tests, with switches to make it fail the way real links and
// EEPROMs do.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "error/error.hpp"
#include "ops/core/cell_access.hpp"
#include "params/param_db.hpp"

namespace i20::ops::testing {

class FakeCard : public CellAccess {
 public:
  // Every writable parameter at its default (working ones at their NV twin's), others 0.
  explicit FakeCard(const params::ParamDb& db) : db_(db) {
    for (const auto& p : db.all()) {
      auto value = p.default_value;
      if (!value && !p.twin.empty()) value = db.get(p.twin).default_value;
      values[p.name] = value.value_or(0);
    }
    values["NVMAXCURRENT"] = values["MAXCURRENT"] = 1000;  // 10 A: the manual gives no default
    // No published factory value either; the simulator's 40 V keeps the pair ordered (35 V below).
    values["NVBUSUNDERVMAX"] = values["BUSUNDERVMAX"] = 4000;
  }

  RawValues read(const std::vector<std::string>& names) override {
    ++read_calls;
    RawValues out;
    for (const auto& name : names) {
      ++reads_of[name];
      if (fail_reads_of.contains(name)) throw Error("injected: no reply reading " + name);
      if (unconfirmed.contains(name)) continue;  // an honest read leaves out what is no fact
      const auto it = values.find(name);
      if (it == values.end()) throw Error("fake card has no " + name);
      out[name] = it->second;
    }
    return out;
  }

  void check_write(const std::string& name, std::int64_t) override {
    if (refuse_writes_to.contains(name))
      throw Error(name + ": address not confirmed for this firmware", ErrorKind::Refused,
                  Advice::AllowUnverified);
  }

  void write(const std::string& name, std::int64_t raw) override {
    ++write_calls;
    if (before_write) before_write(name, write_calls);
    const bool fail = fail_write_calls.contains(write_calls) || fail_writes_to.contains(name);
    if (fail && !failed_write_lands) throw Error("injected: link timeout writing " + name);
    values.at(name) = raw;
    if (const auto corrupt = corrupt_writes.find(name); corrupt != corrupt_writes.end()) {
      values.at(name) = corrupt->second;  // once: a later write (the restore) sticks
      corrupt_writes.erase(corrupt);
    }
    if (fail) throw Error("injected: reply lost after writing " + name);
    log.emplace_back(name, raw);
  }

  void reset() override {
    if (fail_reset) throw Error("injected: card did not come back after reset");
    ++resets;
    for (const auto& p : db_.all())
      if (p.is_nv() && !p.twin.empty()) values[p.twin] = values[p.name];
  }

  std::string describe() override { return "fake 8I20 unit 0x00C0FFEE"; }

  // State and switches, public on purpose: tests set them up and inspect them.
  RawValues values;
  std::vector<std::pair<std::string, std::int64_t>> log;  // writes that succeeded
  int write_calls = 0;
  int read_calls = 0;
  int resets = 0;
  std::set<int> fail_write_calls;                      // 1-based write() calls that throw
  std::set<std::string> fail_writes_to;                // every write to these throws
  bool failed_write_lands = false;                     // a failing write still changes the cell
  std::map<std::string, std::int64_t> corrupt_writes;  // next write silently stores this instead
  std::set<std::string> fail_reads_of;
  std::map<std::string, int> reads_of;     // how often each cell was asked for
  std::set<std::string> unconfirmed;       // addresses not confirmed for this firmware: never read
  std::set<std::string> refuse_writes_to;  // check_write() refuses these
  bool fail_reset = false;
  std::function<void(const std::string&, int)> before_write;

 private:
  const params::ParamDb& db_;
};

}  // namespace i20::ops::testing
