// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/amp.hpp"

#include <algorithm>
#include <csignal>
#include <thread>
#include <utility>

#include "device/discover.hpp"
#include "device/errors.hpp"
#include "eth/errors.hpp"
#include "lbp/bytes.hpp"
#include "ops/core/timing.hpp"

namespace i20::ops {
namespace {

// Larger than any RPC table the 8I20 has (64 RPCs of 8 bytes): a size beyond it is not an
// RPC table worth reading.
constexpr std::size_t kMaxRpcTableBytes = 512;

std::vector<params::ParamDb::Evidence> rpc_evidence(const device::RpcEvidence& decoded, std::string& note) {
  std::vector<params::ParamDb::Evidence> evidence;
  for (const auto& [name, address] : decoded.addresses)
    evidence.push_back({name, address, "the card's pre-loaded RPC table, " + decoded.note});
  note = decoded.note;
  return evidence;
}

// Card names are four ASCII letters; anything else is shown as hex escapes.
std::string printable(const std::string& name) {
  std::string out;
  for (unsigned char c : name)
    out += (c >= 0x20 && c < 0x7F) ? std::string(1, static_cast<char>(c))
                                   : "\\x" + lbp::hex_value(c, 2).substr(2);
  return out;
}

}  // namespace

void Cancel::check(const std::string& what) const {
  if (requested()) throw device::Cancelled("interrupted (" + cause() + ") while " + what);
}

std::string Cancel::cause() const {
  switch (stop_ ? stop_->signal() : 0) {
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "Ctrl-C";
  }
}

Amp::Amp(std::unique_ptr<link::Link> link, Endpoint endpoint, RetryPolicy retry, Cancel cancel,
         std::chrono::steady_clock::time_point opened_at)
    : link_(std::move(link)),
      endpoint_(std::move(endpoint)),
      retry_(retry),
      cancel_(cancel),
      deadline_(opened_at + retry.operation_deadline) {}

// The operation's deadline counts from here: opening the link (the port's setup over
// Ethernet) and identifying the card spend the same time as the command's own work.
std::unique_ptr<Amp> Amp::open(const Endpoint& endpoint, const params::ParamDb& loaded,
                               const OpenOptions& options, Cancel cancel) {
  cancel.check("connecting");
  const auto opened_at = std::chrono::steady_clock::now();
  std::unique_ptr<link::Link> link;
  {
    const link::WaitBound bounded(opened_at + options.retry.operation_deadline);
    link = open_link(endpoint, loaded, options.link, options.retry);
  }
  std::unique_ptr<Amp> amp(new Amp(std::move(link), endpoint, options.retry, cancel, opened_at));
  amp->identify(loaded);
  return amp;
}

std::unique_ptr<Amp> Amp::attach(std::unique_ptr<link::Link> link, Endpoint endpoint,
                                 const params::ParamDb& loaded, RetryPolicy retry, Cancel cancel,
                                 std::chrono::steady_clock::time_point opened_at) {
  std::unique_ptr<Amp> amp(new Amp(std::move(link), std::move(endpoint), retry, cancel, opened_at));
  amp->identify(loaded);
  return amp;
}

Amp::Settling::Settling(Amp& amp) : amp_(amp), was_settling_(std::exchange(amp.settling_, true)) {}

Amp::Settling::~Settling() {
  amp_.settling_ = was_settling_;
}

std::chrono::steady_clock::time_point Amp::bound() const {
  if (!settling_) return deadline_;
  const auto restore_bound = deadline_ + timing::kSettleBudget;
  return leave_mode_bound_ ? std::max(restore_bound, *leave_mode_bound_) : restore_bound;
}

void Amp::require_time_left() const {
  if (std::chrono::steady_clock::now() < bound()) return;
  throw link::OutOfTime("the command's time was up (" +
                        std::to_string(retry_.operation_deadline.count() / 1000) +
                        " s from opening the card" + (settling_ ? ", and the time to settle it after" : "") +
                        ") before the next exchange with " + endpoint_.text + "; it was not sent");
}

void Amp::identify(const params::ParamDb& loaded) {
  // The identity reads use only public addresses (SWREVISION, UNITNUMBER).
  device::Amp8i20 bootstrap(*link_, loaded, timing::amp(), cancel_.flag());
  identity_.info = with_retries([&] { return bootstrap.info(); });
  const auto& info = identity_.info;
  if (info.card_name != "8I20")
    // No 8I20 was reached (exit 1): another Mesa card answers there, or the port is another device's.
    throw Error("the card on " + link_->describe() + " answers as '" + printable(info.card_name) +
                "', not as an 8I20: check the port or channel; this tool only knows the 8I20's parameters");
  if (info.nv_access != lbp::local::NvAccess::Ram || info.rpcmem) {
    // A stop request now must not leave the card in the mode an earlier session left on.
    uninterruptible_ = true;
    const Settling way_back(*this);
    identity_.modes_left = with_retries([&] { return bootstrap.leave_modes(); });
    uninterruptible_ = false;
  }

  auto resolved = loaded.for_firmware(*info.swrevision);
  const auto evidence = read_rpc_evidence(resolved);
  for (const auto& e : evidence) identity_.rpc_confirmed.push_back(e.name);
  resolved = resolved.with_evidence(evidence);
  db_ = std::make_unique<params::ParamDb>(std::move(resolved));
  amp_ = std::make_unique<device::Amp8i20>(*link_, *db_, timing::amp(), cancel_.flag());
  identity_.info.working_map_confirmed = device::working_map_confirmed(*db_);
}

Amp::Uninterruptible::Uninterruptible(Amp& amp) : amp_(amp) {
  amp_.uninterruptible_ = true;
  amp_.device().set_cancel(nullptr);
}

Amp::Uninterruptible::~Uninterruptible() {
  amp_.uninterruptible_ = false;
  amp_.device().set_cancel(amp_.cancel_.flag());
}

// The table is read a slice at a time until SSLBP's cycle RPC decodes, so a card whose
// cycle RPC sits near the start costs a few commands, not the whole table. A table that
// cannot be read is not fatal: the card then confirms nothing by itself, and says so.
std::vector<params::ParamDb::Evidence> Amp::read_rpc_evidence(const params::ParamDb& resolved) {
  constexpr std::size_t kSlice = 64;
  const std::size_t size = identity_.info.rpc_size;
  if (size == 0 || size > kMaxRpcTableBytes) {
    identity_.rpc_note = "the card reports no usable RPC table (" + std::to_string(size) + " bytes)";
    return {};
  }
  device::Amp8i20 reader(*link_, resolved, timing::amp(), cancel_.flag());
  lbp::Bytes table;
  device::RpcEvidence decoded;
  try {
    while (table.size() < size && decoded.addresses.empty()) {
      const std::size_t count = std::min(kSlice, size - table.size());
      const auto slice = with_retries([&] { return reader.read_rpc_table(table.size(), count); });
      table.insert(table.end(), slice.begin(), slice.end());
      decoded = device::decode_rpc_evidence(table);
    }
  } catch (const link::OutOfTime&) {
    throw;  // the command ends: nothing is left to confirm addresses for
  } catch (const link::LinkError& e) {
    identity_.rpc_note = std::string("the RPC table could not be read (") + e.what() + ")";
    return {};
  }
  return rpc_evidence(decoded, identity_.rpc_note);
}

void Amp::answered() {
  if (silent_since_) ++silences_ended_;
  silent_since_.reset();
}

void Amp::unanswered(const link::LinkError&) {
  if (!silent_since_) silent_since_ = std::chrono::steady_clock::now();
}

// Line faults and a silent card heal; a host that took the port or a command the transport
// cannot carry do not, so they are not waited for.
bool Amp::wait_for_answer(const link::LinkError& e) {
  if (dynamic_cast<const eth::ForeignHostError*>(&e) || dynamic_cast<const link::UnsupportedCommand*>(&e))
    return false;
  using Clock = std::chrono::steady_clock;
  if (past_deadline()) return false;
  const auto deadline = std::min(silent_since_.value_or(Clock::now()) + retry_.silence_window, bound());
  if (Clock::now() >= deadline) return false;
  const auto until = std::min(deadline, Clock::now() + retry_.probe_interval);
  // In short slices, so that a stop request is obeyed at once where the card may be stopped.
  while (Clock::now() < until) {
    if (!uninterruptible_) cancel_.check("waiting for the card to answer again");
    std::this_thread::sleep_for(std::min<Clock::duration>(until - Clock::now(), timing::kStopPollSlice));
  }
  ++probes_;
  return true;
}

std::string Amp::settle() {
  const std::string mode = amp_->unsettled_mode();
  unsettled_said_ = false;
  if (mode.empty()) return {};
  // A stop request does not end this (it is the way out), so the card is uninterruptible
  // meanwhile, silence window included. It has a budget of its own from now, however much
  // of the command's time the restores before it took.
  const bool was_uninterruptible = std::exchange(uninterruptible_, true);
  const Settling way_back(*this);
  // Once per operation: a second settle (the session's, after the use case's) gets what is
  // left of the first one's budget, not a budget of its own.
  if (!leave_mode_bound_) leave_mode_bound_ = std::chrono::steady_clock::now() + timing::kLeaveModeBudget;
  const link::WaitBound bounded(bound());
  for (unsigned attempt = 1;; ++attempt) {
    cancel_.acknowledge("leaving " + mode);
    try {
      amp_->leave_modes();
      answered();
      uninterruptible_ = was_uninterruptible;
      return mode;
    } catch (const link::OutOfTime&) {
      break;  // its own budget is spent: nothing more is sent
    } catch (const link::LinkError& e) {
      unanswered(e);
      ++retries_;
      if (attempt >= retry_.attempts && !wait_for_answer(e)) break;
    } catch (const Error&) {
      ++retries_;
      if (attempt >= retry_.attempts) break;
    }
  }
  uninterruptible_ = was_uninterruptible;
  unsettled_said_ = true;
  // Past the bound the card may have been answering late rather than not at all: say which.
  const bool time_up = std::chrono::steady_clock::now() >= bound();
  const std::string what = time_up
                               ? " had not confirmed leaving " + mode + " when the time to settle it ran out"
                               : " stopped answering while in " + mode;
  throw device::AmpStateError(
      "the 8I20 on " + endpoint_.text + what +
      " and may still be in it: when it answers again, run any i20 command on it (it leaves "
      "the mode first), or `i20 " +
      endpoint_.flags() + " reset`, before the machine uses it");
}

std::string Amp::describe() const {
  const auto& info = identity_.info;
  return info.card_name + " unit " + lbp::hex_value(info.unit_number.value_or(0), 8) + ", SWREVISION " +
         lbp::hex_value(info.swrevision.value_or(0), 4) + ", on " + endpoint_.text;
}

std::string Amp::unconfirmed_reason(const params::Param& param) const {
  if (!param.address) return "address not known (" + param.provenance.source + ")";
  if (db_->address_confirmed(param)) return {};
  return "address not confirmed for SWREVISION " + lbp::hex_value(swrevision(), 4);
}

}  // namespace i20::ops
