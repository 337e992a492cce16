// SPDX-License-Identifier: GPL-2.0-or-later
#include "ops/core/amp_cell_access.hpp"

#include "device/errors.hpp"
#include "lbp/bytes.hpp"
#include "link/link.hpp"
#include "ops/core/read.hpp"
#include "ops/core/timing.hpp"
#include "params/value.hpp"

namespace i20::ops {

// The transaction decides when Ctrl-C stops the work (before the first write, between
// writes, never inside a rollback), so the card client under it must not throw Cancelled
// in the middle of an EEPROM sequence or of a restore: its own polling is off meanwhile.
AmpCellAccess::AmpCellAccess(Amp& amp, device::WriteOptions write, Activity activity)
    : amp_(amp), uninterruptible_(amp), write_(write), activity_(std::move(activity)) {}

void AmpCellAccess::note(const std::string& what) {
  if (activity_) activity_(what);
}

RawValues AmpCellAccess::read(const std::vector<std::string>& names) {
  if (!failed_ && written_ == 0) note("reading");
  RawValues out;
  // Reads change nothing on the card, so they are simply asked again: read_values when a
  // reply is lost (Amp::with_retries, the retry budget), here when the card reset in the
  // middle of an NV read.
  for (unsigned attempt = 1;; ++attempt) {
    try {
      // With --allow-unverified the user vouches for the addresses: their values count.
      const auto unconfirmed = write_.allow_unverified ? Unconfirmed::Read : Unconfirmed::Skip;
      for (const auto& r : read_values(amp_, names, unconfirmed))
        if (r.raw) out[r.param->name] = *r.raw;
      return out;
    } catch (const device::AmpStateError&) {
      if (attempt >= amp_.retry().attempts || amp_.past_deadline()) throw;
      amp_.count_retry();
    }
  }
}

void AmpCellAccess::check_write(const std::string& name, std::int64_t raw) {
  ++planned_;
  try {
    amp_.device().check_write(amp_.db().get(name), raw, write_);
  } catch (const device::SafetyError&) {
    refused_ = true;
    throw;
  }
}

void AmpCellAccess::way_back() {
  if (!settling_) settling_.emplace(amp_);
}

void AmpCellAccess::write(const std::string& name, std::int64_t raw) {
  // After a stop request the transaction writes only to restore (it stops before the next write).
  const bool restoring = failed_ || written_ >= planned_ || amp_.cancel().requested();
  // Every exchange of the write (NV access, the write, its read-back) ends by the bound; a
  // write of the change itself is not begun once the operation's time is up.
  const link::WaitBound bounded(amp_.bound());
  if (restoring)
    note("restoring " + name);
  else
    note("writing " + name + " (" + std::to_string(written_ + 1) + "/" + std::to_string(planned_) + ")");
  try {
    amp_.require_time_left();
    write_once(name, raw);
  } catch (...) {
    failed_ = true;
    throw;
  }
  if (!restoring) ++written_;
}

// A lost or garbled reply says nothing about whether the write landed: the card is asked
// what it holds, and the write is repeated (writing the same value again is harmless) only
// when that read-back shows the card does not hold the value yet, and only within the retry
// budget. A read-back that gets no answer either leaves the write's fate unknown: the
// error stands, nothing is written blindly. A read-back that disagrees with a completed
// exchange (VerifyError) is an answer, not a line fault: it is not retried.
void AmpCellAccess::write_once(const std::string& name, std::int64_t raw) {
  const unsigned attempts = amp_.retry().attempts;
  for (unsigned attempt = 1;; ++attempt) {
    try {
      const auto report = amp_.device().write(name, raw, write_);
      if (!report.verified)
        throw device::VerifyError(name + " was written but the card cannot read it back to verify it");
      return;
    } catch (const link::OutOfTime&) {
      throw;  // not sent: nothing to read back
    } catch (const device::NvModeLost& lost) {
      recover_from_mode_loss(lost);
      const auto held = holds(name, raw);
      if (held == true) return;
      if (!held || attempt >= attempts || amp_.past_deadline()) throw;
    } catch (const link::LinkError& e) {
      amp_.unanswered(e);
      const auto held = holds(name, raw);
      if (held == true) return;
      if (!held || attempt >= attempts || amp_.past_deadline()) throw;
    } catch (const device::AmpStateError&) {
      // Leaving NV mode failed after the write. An NV read-back enters and leaves NV mode
      // again, so a successful one also proves the card is back in normal access mode.
      const auto held = holds(name, raw);
      if (held == true) return;
      if (!held || attempt >= attempts || amp_.past_deadline()) throw;
    }
    amp_.count_retry();
  }
}

// The card reset while an EEPROM cell was written. Its working values were reloaded from
// the EEPROM as it was then. If working memory at the EEPROM address now holds the value
// written, the write went there instead: a reset re-initialises that memory, and the card
// has just reset anyway, so it is reset once more before anything else is sent.
void AmpCellAccess::recover_from_mode_loss(const device::NvModeLost& lost) {
  events_.push_back("the card reset itself while " + lost.cell() +
                    " was being written: its working values were reloaded from the EEPROM as it was then");
  if (!lost.stray_ram_value()) return;
  note("resetting");
  amp_.device().reset(timing::kResetWait);
  events_.push_back("working memory at " + lbp::hex_value(lost.address(), 4) + " held the value meant for " +
                    lost.cell() + "'s EEPROM cell: the tool reset the card to re-initialise it");
}

// read_values repeats a read whose reply is lost (Amp::with_retries): that spends the
// budget, so a lost read-back is not repeated here on top. Only a card that reset in the
// middle of an NV read-back (AmpStateError) is asked again, within the same budget.
std::optional<bool> AmpCellAccess::holds(const std::string& name, std::int64_t raw) {
  for (unsigned attempt = 1;; ++attempt) {
    try {
      const auto unconfirmed = write_.allow_unverified ? Unconfirmed::Read : Unconfirmed::Skip;
      const auto r = read_values(amp_, std::vector<std::string>{name}, unconfirmed);
      return r.front().raw == raw;
    } catch (const link::LinkError&) {
      return std::nullopt;
    } catch (const device::AmpStateError&) {
      if (attempt >= amp_.retry().attempts || amp_.past_deadline()) return std::nullopt;
      amp_.count_retry();
    }
  }
}

void AmpCellAccess::reset() {
  const link::WaitBound bounded(amp_.bound());
  amp_.require_time_left();
  note("resetting");
  amp_.device().reset(timing::kResetWait);
}

}  // namespace i20::ops
