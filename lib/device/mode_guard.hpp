// SPDX-License-Identifier: GPL-2.0-or-later
// RAII guards for the two card modes that must never outlive an operation: NV (EEPROM)
// access (docs/facts.md s2: NV mode goes back to RAM access on every path, errors included) and
// RPC memory access (manual: "The RPCMEM access flag must be clear for normal operation").
#pragma once

#include <string>

#include "device/suspend_hold.hpp"
#include "lbp/command.hpp"
#include "link/link.hpp"

namespace i20::device {

class ModeGuard {
 public:
  // The guard is armed: the caller has sent (or is about to send, in the same batch)
  // the command that enters the mode. `leave` is the command that ends it, `confirm` the
  // local read that answers 0 once the mode is off: a local write has no reply, so only the
  // read after it proves the card acted on it. When leaving fails (also from the
  // destructor, which cannot throw), the mode's name goes to `unsettled`, so whoever owns
  // the card can say the card may still be in it.
  // `tries`: sends of the leave batch before the mode counts as possibly still on.
  ModeGuard(link::Link& link, lbp::Command leave, lbp::Command confirm, std::string what, unsigned tries,
            std::string* unsettled = nullptr);
  ~ModeGuard();
  ModeGuard(const ModeGuard&) = delete;
  ModeGuard& operator=(const ModeGuard&) = delete;

  // The leave command and its confirming read went out in a batch that completed, and
  // `confirmed` is that read's reply: the mode is settled (an earlier failure to leave it
  // too), or, when the card still reports the mode, AmpStateError.
  void disarm(const lbp::Bytes& confirmed);
  // Leaves the mode now; throws AmpStateError if the card does not confirm.
  void leave();

 private:
  SuspendHold no_suspend_;  // Ctrl-Z waits until the mode is left (suspend_hold.hpp)
  link::Link& link_;
  lbp::Command leave_;
  lbp::Command confirm_;
  std::string what_;
  unsigned tries_;
  [[noreturn]] void still_on();
  void settled() {
    if (unsettled_ && *unsettled_ == what_) unsettled_->clear();
  }

  std::string* unsettled_;
  bool armed_ = true;
};

}  // namespace i20::device
