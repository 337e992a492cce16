// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/inventory.hpp"

#include <thread>

#include "device/errors.hpp"
#include "eth/target.hpp"
#include "ops/core/read.hpp"

namespace i20::ops {
namespace {

std::string linuxcnc_name_of(const Endpoint& target) {
  if (!target.is_eth()) return {};
  const auto t = target.eth_target();
  return "8i20." + std::to_string(t.sserial_port) + "." + std::to_string(t.channel);
}

void read_faults(Amp& amp, InventoryRow& row) {
  try {
    row.faults = read_fault_registers(amp);
  } catch (
      const device::SafetyError& e) {  // FAULT/STATUS not confirmed for this firmware: unknown, not guessed
    row.faults_error = e.what();
  }
}

void read_row(Amp& amp, const InventoryJob& job, InventoryRow& row) {
  row.identity = amp.identity();
  row.card = amp.describe();
  read_faults(amp, row);
  if (job.profile) row.diff = diff_card(amp, *job.profile);
  row.outcome = Outcome::Done;
}

InventoryRow read_one(const Endpoint& target, const InventoryJob& job) {
  InventoryRow row;
  row.target = target;
  row.linuxcnc_name = linuxcnc_name_of(target);
  try {
    const auto amp = Amp::open(target, *job.db, job.open, job.cancel);
    try {
      read_row(*amp, job, row);
      amp->settle();
    } catch (...) {
      try {
        amp->settle();  // never leave NV access mode on, whatever stopped the read
      } catch (const Error&) {
        row.outcome = Outcome::Uncertain;
      }
      throw;
    }
  } catch (const Error& e) {
    row.error = e.what();
    if (row.outcome != Outcome::Uncertain) row.outcome = outcome_of(e.kind());
  } catch (const std::exception& e) {
    row.error = e.what();
    row.outcome = Outcome::Failed;
  }
  return row;
}

}  // namespace

std::optional<bool> InventoryRow::matches() const {
  if (!reached() || !outcome_ok()) return std::nullopt;
  return profile_matches(diff);
}

bool InventoryRow::outcome_ok() const {
  return exit_code(outcome) == kExitOk;
}

std::optional<bool> profile_matches(const std::vector<profile::DiffRow>& rows) {
  bool all = true;
  for (const auto& r : rows) {
    if (!r.card_raw) return std::nullopt;
    all = all && r.equal;
  }
  return all;
}

std::vector<profile::DiffRow> diff_card(Amp& amp, const profile::Profile& profile) {
  std::vector<std::string> names;
  for (const auto& w : profile::cell_writes(profile, amp.db())) names.push_back(w.cell);
  profile::RawValues values;
  for (const auto& r : read_values(amp, names))
    if (r.fact()) values[r.param->name] = *r.raw;
  return profile::diff(profile, amp.db(), values);
}

std::vector<InventoryRow> read_inventory(const std::vector<Endpoint>& targets, const InventoryJob& job) {
  std::vector<InventoryRow> rows(targets.size());
  std::vector<std::thread> threads;
  for (const auto& line : group_by_line(targets, true))
    threads.emplace_back([&, line] {
      for (const std::size_t i : line) rows[i] = read_one(targets[i], job);
    });
  for (auto& t : threads) t.join();
  return rows;
}

Outcome inventory_outcome(const std::vector<InventoryRow>& rows) {
  Outcome worst = Outcome::Done;
  for (const auto& r : rows) worst = most_serious(worst, r.outcome);
  return worst;
}

}  // namespace i20::ops
