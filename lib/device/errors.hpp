// Errors of the device layer. SafetyError means nothing was sent to the card.
#pragma once

#include "lbp/error.hpp"

namespace i20::device {

// A write the safety rules refuse (range, unconfirmed address, guarded parameter,
// read-only). Raised before any byte goes on the wire.
class SafetyError : public Error {
 public:
  using Error::Error;
};

// The card accepted a write but reads back something else.
class VerifyError : public Error {
 public:
  using Error::Error;
};

// The card may be left in a mode it must not stay in (NV access, RPC memory access):
// the message says what to do (reset or power-cycle).
class CardStateError : public Error {
 public:
  using Error::Error;
};

// The user interrupted (Ctrl-C). Raised between exchanges, after cleanup.
class Cancelled : public Error {
 public:
  using Error::Error;
};

}  // namespace i20::device
