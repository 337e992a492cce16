// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/faults.hpp"

#include <utility>

#include "device/errors.hpp"
#include "faults/fault_mask.hpp"
#include "lbp/bytes.hpp"
#include "ops/change.hpp"
#include "ops/core/read.hpp"

namespace i20::ops {
namespace {

std::optional<double> scaled(const Reading& r) {
  if (!r.fact()) return std::nullopt;
  return static_cast<double>(*r.raw) * r.param->scale;
}

const params::Param& fact_required(Amp& amp, const char* name) {
  const params::Param& p = amp.db().get(name);
  if (!p.address || !amp.db().address_confirmed(p))
    throw device::SafetyError(std::string(name) + " cannot be read as a fact on " + amp.describe() + ": " +
                              amp.unconfirmed_reason(p) +
                              ", and the card's RPC table did not name it; `i20 " + amp.endpoint().flags() +
                              " discover` may find it");
  return p;
}

// CLEARFAULT was written but the clear did not finish: what the card says now decides
// between "faults remain" (exit 5) and "uncertain" (exit 4). Always throws.
[[noreturn]] void explain_unfinished_clear(Amp& amp, const Error& e) {
  FaultReadings now;
  try {
    now = read_fault_registers(amp);
  } catch (const Error& again) {
    if (again.kind() == ErrorKind::Cancelled) throw;
    throw device::AmpStateError(std::string(e.what()) + "; FAULT could not be read after it (" +
                                again.what() + ")");
  }
  if (now.fault != 0)
    throw Error(std::string(e.what()) + "; FAULT still reads " + lbp::hex_value(now.fault, 4) +
                    ": faults remain latched",
                ErrorKind::FaultsRemain);
  throw device::AmpStateError(std::string(e.what()) +
                              "; FAULT reads 0x0000 now, but the card may still act on "
                              "the pending CLEARFAULT");
}

}  // namespace

FaultReadings read_fault_registers(Amp& amp) {
  const auto& db = amp.db();
  std::vector<const params::Param*> list{&fact_required(amp, "FAULT"), &fact_required(amp, "STATUS")};
  for (const char* name : {"FAULTMASK", "BUSV", "TEMPERATURE", "BUSUNDERV", "BUSOVERV", "BRAKEONV"})
    if (const auto* p = db.find(name)) list.push_back(p);
  FaultReadings r;
  for (const auto& v : read_values(amp, list)) {
    if (!v.fact()) {
      r.not_confirmed.push_back(v.param->name);
      continue;
    }
    const std::string& n = v.param->name;
    const auto raw16 = static_cast<std::uint16_t>(*v.raw);
    if (n == "FAULT") r.fault = raw16;
    if (n == "STATUS") r.status = raw16;
    if (n == "FAULTMASK") r.faultmask = raw16;
    if (n == "BUSV") r.busv_v = scaled(v);
    if (n == "TEMPERATURE") r.temperature_c = scaled(v);
    if (n == "BUSUNDERV") r.busunderv_v = scaled(v);
    if (n == "BUSOVERV") r.busoverv_v = scaled(v);
    if (n == "BRAKEONV") r.brakeonv_v = scaled(v);
  }
  return r;
}

FaultClear::FaultClear(const params::ParamDb& db, const device::WriteOptions& write,
                       std::chrono::milliseconds wait)
    : write_(write), wait_(wait) {
  device::check_offline(db.get("CLEARFAULT"), 1, write);
}

faults::Report ClearResult::cleared() const {
  return faults::fault_report(static_cast<std::uint16_t>(fault_before & ~after.fault));
}

faults::Report ClearResult::remaining() const {
  return faults::fault_report(after.fault, after.faultmask);
}

ClearResult FaultClear::run_on(Amp& amp) const {
  const auto& write = write_;
  const auto wait = wait_;
  amp.device().check_write(amp.db().get("CLEARFAULT"), 1, write);
  fact_required(amp, "FAULT");
  ClearResult result;
  device::ClearFaultsResult done;
  try {
    done = amp.device().clear_faults(write, wait);
  } catch (const Error& e) {
    if (e.kind() != ErrorKind::Uncertain) throw;
    explain_unfinished_clear(amp, e);
  }
  result.fault_before = done.fault_before;
  result.took = done.took;
  // Again with the measurements, so every remaining bit can say why it is still there.
  result.after = read_fault_registers(amp);
  return result;
}

FaultMaskChange::FaultMaskChange(const params::ParamDb& db, std::string key, bool masked,
                                 const device::WriteOptions& write)
    : key_(std::move(key)), masked_(masked), write_(write) {
  faults::maskable_fault(key_);  // unknown or unmaskable: refused before anything is read
  device::check_offline(db.get("FAULTMASK"), faults::kNothingMasked, write_);
}

MaskResult FaultMaskChange::run_on(Amp& amp) const {
  const auto& key = key_;
  const bool masked = masked_;
  const auto& write = write_;
  const auto& param = amp.db().get("FAULTMASK");
  amp.device().check_write(param, faults::kNothingMasked, write);
  MaskResult result;
  const auto unconfirmed = write.allow_unverified ? Unconfirmed::Read : Unconfirmed::Skip;
  const auto now = read_values(amp, std::vector<const params::Param*>{&param}, unconfirmed);
  if (!now.front().raw)
    throw device::SafetyError("FAULTMASK cannot be read as a fact on " + amp.describe() + ": " +
                              now.front().reason);
  result.before = static_cast<std::uint16_t>(*now.front().raw);
  result.wanted = faults::set_fault_masked(result.before, key, masked);
  const ValueChange change({.values = {{"FAULTMASK", std::to_string(result.wanted)}},
                            .syntax = ValueSyntax::Raw,
                            .force = write.force,
                            .allow_unverified = write.allow_unverified,
                            .cancel = amp.cancel()},
                           amp.db());
  result.run = change.run_on(amp);
  if (result.run.ok()) result.after = read_fault_registers(amp);
  return result;
}

}  // namespace i20::ops
