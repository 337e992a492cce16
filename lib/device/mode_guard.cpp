#include "device/mode_guard.hpp"

#include "device/errors.hpp"

namespace i20::device {

ModeGuard::ModeGuard(link::Link& link, lbp::Command leave, std::string what, std::string* unsettled)
    : link_(link), leave_(std::move(leave)), what_(std::move(what)), unsettled_(unsettled) {}

ModeGuard::~ModeGuard() {
  if (!armed_) return;
  // Destructors must not throw; a failure here is reported by leave() callers that
  // care, and the card's reset clears the mode anyway.
  try {
    leave();
  } catch (...) {
  }
}

void ModeGuard::leave() {
  // Two attempts: the first may fail right after the error that brought us here.
  for (int attempt = 0; attempt < 2; ++attempt) {
    try {
      link_.execute_one(leave_);
      armed_ = false;
      settled();
      return;
    } catch (const link::LinkError&) {
    }
  }
  armed_ = false;
  if (unsettled_) *unsettled_ = what_;
  throw CardStateError("could not take the 8I20 out of " + what_ + " on " + link_.describe() +
                       ": reset it (i20 reset) or cycle its logic power before using it");
}

}  // namespace i20::device
