#include "amp_card_access.hpp"

#include <cstdio>

#include "device/errors.hpp"
#include "interrupt.hpp"
#include "lbp/bytes.hpp"
#include "link/link.hpp"
#include "params/value.hpp"

namespace i20::cli {
namespace {}  // namespace

AmpCardAccess::AmpCardAccess(device::Amp8i20& amp, CardAccessOptions options, Activity activity)
    : amp_(amp), options_(std::move(options)), activity_(std::move(activity)) {}

// Ctrl-C stops the forward work once: the engine then restores what it wrote, and those
// restoring calls must go through, or Ctrl-C would leave the card half written. (That is
// also why the Amp8i20 under this adapter gets no cancel flag of its own; NV mode is
// left by the device layer's guards on every path either way.)
void AmpCardAccess::stop_if_interrupted() {
  if (interrupted_ || !app::interrupted()) return;
  interrupted_ = true;
  throw device::Cancelled("interrupted (Ctrl-C)");
}

void AmpCardAccess::note(const std::string& what) {
  if (activity_) activity_(what);
}

profile::RawValues AmpCardAccess::read(const std::vector<std::string>& names) {
  stop_if_interrupted();
  if (!failed_ && written_ == 0) note("reading");
  for (unsigned attempt = 1;; ++attempt) {
    try {
      return read_once(names);
    } catch (const link::LinkError&) {
      // Reading changes nothing on the card, so it can simply be asked again.
      if (attempt >= options_.attempts) throw;
      ++retries_;
    }
  }
}

profile::RawValues AmpCardAccess::read_once(const std::vector<std::string>& names) {
  std::vector<const params::Param*> params;
  for (const auto& name : names) params.push_back(&amp_.db().get(name));
  profile::RawValues out;
  for (const auto& value : amp_.read(params)) out[value.param->name] = value.raw;
  return out;
}

void AmpCardAccess::check_write(const std::string& name, std::int64_t raw) {
  ++planned_;
  try {
    amp_.check_write(amp_.db().get(name), raw, options_.write);
  } catch (const device::SafetyError&) {
    refused_ = true;
    throw;
  }
}

void AmpCardAccess::write(const std::string& name, std::int64_t raw) {
  stop_if_interrupted();
  const bool restoring = failed_ || written_ >= planned_;
  if (restoring)
    note("restoring " + name);
  else
    note("writing " + name + " (" + std::to_string(written_ + 1) + "/" + std::to_string(planned_) + ")");
  try {
    write_once(name, raw);
  } catch (...) {
    failed_ = true;
    throw;
  }
  if (!restoring) ++written_;
}

// A lost or garbled reply says nothing about whether the write landed: the card is asked
// what it holds, and the write repeated (writing the same value again is harmless) until
// the read-back shows the value or the attempts run out. A read-back that disagrees with
// a completed exchange (VerifyError) is an answer, not a line fault: it is not retried.
void AmpCardAccess::write_once(const std::string& name, std::int64_t raw) {
  for (unsigned attempt = 1;; ++attempt) {
    try {
      const auto report = amp_.write(name, raw, options_.write);
      if (!report.verified)
        throw device::VerifyError(name + " was written but the card cannot read it back to verify it");
      return;
    } catch (const link::LinkError&) {
      if (holds(name, raw)) return;
      if (attempt >= options_.attempts) throw;
    } catch (const device::CardStateError&) {
      // Leaving NV mode failed after the write. An NV read-back enters and leaves NV mode
      // again, so a successful one also proves the card is back in normal access mode.
      if (holds(name, raw)) return;
      if (attempt >= options_.attempts) throw;
    }
    ++retries_;
  }
}

bool AmpCardAccess::holds(const std::string& name, std::int64_t raw) {
  for (unsigned attempt = 1; attempt <= options_.attempts; ++attempt) {
    try {
      return read_once({name}).at(name) == raw;
    } catch (const link::LinkError&) {
      ++retries_;
    }
  }
  return false;
}

void AmpCardAccess::reset() {
  stop_if_interrupted();
  note("resetting");
  amp_.reset();
}

std::string AmpCardAccess::describe() {
  if (!description_.empty()) return description_;
  for (unsigned attempt = 1;; ++attempt) {
    try {
      const auto info = amp_.info();
      description_ = info.card_name + " unit " + lbp::hex_value(info.unit_number.value_or(0), 8) +
                     ", SWREVISION " + lbp::hex_value(info.swrevision.value_or(0), 4) + ", on " +
                     (options_.where.empty() ? amp_.link().describe() : options_.where);
      return description_;
    } catch (const link::LinkError&) {
      if (attempt >= options_.attempts) throw;
      ++retries_;
    }
  }
}

}  // namespace i20::cli
