// SPDX-License-Identifier: GPL-2.0-or-later
// The toolkit's typed errors, below every layer: each message names what was wrong in words
// a user can act on, and its kind says what it means for the card (lib/ops maps the kind to
// an outcome and an exit code, in one place).
#pragma once

#include <stdexcept>
#include <string>

namespace i20 {

// What an error means for the user and the card; apps map it to an exit code in one
// place (lib/ops/core/outcome.hpp).
enum class ErrorKind {
  Failure,       // the card or the line failed; nothing was left half done unreported
  BadInput,      // arguments, files or values are wrong: nothing was sent
  Refused,       // a safety rule refused: nothing was written
  Uncertain,     // the card's state may differ from what was asked: the message names the cells
  FaultsRemain,  // faults stay latched after clearing
  Cancelled,     // the user interrupted, after the card was left in a known state
  OutputLost,    // what the command writes (stdout, a file, a backup, a log) did not land in full
};

// What overrides a refusal. The library says what happened and never names a command-line
// option: each app adds the option that changes it, and only one that program has
// (apps/common/errors.hpp). Errors, transaction results (ops::TransactionResult) and profile
// findings (profile::Finding) carry it.
enum class Advice {
  None,
  RunningHost,      // refused beside a running host: taking the card over, or a passive read
  Force,            // a guarded value or a measured-bus rule: forcing it writes it anyway
  AllowUnverified,  // an address not confirmed for the card's firmware: allowing unverified ones
};

// Base of every error the toolkit raises on purpose.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message, ErrorKind kind = ErrorKind::Failure,
                 Advice advice = Advice::None)
      : std::runtime_error(message), kind_(kind), advice_(advice) {}
  ErrorKind kind() const noexcept { return kind_; }
  // What would override it, for the app to name (Advice::None: nothing does).
  Advice advice() const noexcept { return advice_; }

 private:
  ErrorKind kind_;
  Advice advice_;
};

// Arguments, files or values that are wrong, in any layer (a data size the protocol cannot
// express, an unknown option, a bad value): nothing was sent.
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

// What the command was to write did not land in full (a full disk, a closed pipe, a
// folder gone): no partial file is left, and the card is as the rest of the output says.
class OutputError : public Error {
 public:
  explicit OutputError(const std::string& message) : Error(message, ErrorKind::OutputLost) {}
};

}  // namespace i20
