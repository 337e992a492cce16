// SPDX-License-Identifier: GPL-2.0-or-later
// Errors of the device layer. SafetyError means nothing was sent to the card.
#pragma once

#include "error/error.hpp"

namespace i20::device {

// A write the safety rules refuse (range, unconfirmed address, guarded parameter,
// read-only). Raised before any byte goes on the wire. `advice`: what overrides it, if
// anything (the app names the option).
class SafetyError : public Error {
 public:
  explicit SafetyError(const std::string& message, Advice advice = Advice::None)
      : Error(message, ErrorKind::Refused, advice) {}
};

// The card accepted a write but reads back something else.
class VerifyError : public Error {
 public:
  explicit VerifyError(const std::string& message) : Error(message, ErrorKind::Uncertain) {}
};

// The card may be left in a mode it must not stay in (NV access, RPC memory access):
// the message says what to do (reset or power-cycle).
class AmpStateError : public Error {
 public:
  explicit AmpStateError(const std::string& message) : Error(message, ErrorKind::Uncertain) {}
};

// The user interrupted (Ctrl-C). Raised between exchanges, after cleanup.
class Cancelled : public Error {
 public:
  explicit Cancelled(const std::string& message) : Error(message, ErrorKind::Cancelled) {}
};

}  // namespace i20::device
