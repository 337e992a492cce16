// SPDX-License-Identifier: GPL-2.0-or-later
#include "device/mode_guard.hpp"

#include "device/errors.hpp"

namespace i20::device {

ModeGuard::ModeGuard(link::Link& link, lbp::Command leave, lbp::Command confirm, std::string what,
                     unsigned tries, std::string* unsettled)
    : link_(link),
      leave_(std::move(leave)),
      confirm_(std::move(confirm)),
      what_(std::move(what)),
      tries_(tries),
      unsettled_(unsettled) {}

ModeGuard::~ModeGuard() {
  if (!armed_) return;
  // Destructors must not throw; a failure here is recorded in `unsettled` for the card's
  // owner to report, and the card's reset clears the mode anyway.
  try {
    leave();
  } catch (...) {
  }
}

void ModeGuard::disarm(const lbp::Bytes& confirmed) {
  armed_ = false;
  if (confirmed.empty() || confirmed.at(0) != 0) still_on();
  settled();
}

void ModeGuard::still_on() {
  armed_ = false;
  if (unsettled_) *unsettled_ = what_;
  throw AmpStateError("the 8I20 on " + link_.describe() + " did not confirm that it left " + what_ +
                      ": reset it (i20 reset) or cycle its logic power before using it");
}

void ModeGuard::leave() {
  // The caller's tries: the first may fail right after the error that brought us here.
  for (unsigned attempt = 0; attempt < tries_; ++attempt) {
    try {
      const auto replies = link_.execute(std::vector<lbp::Command>{leave_, confirm_});
      if (replies.at(1).at(0) != 0) continue;  // told to leave, still in it: once more
      armed_ = false;
      settled();
      return;
    } catch (const link::LinkError&) {
    }
  }
  still_on();
}

}  // namespace i20::device
