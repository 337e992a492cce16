// SPDX-License-Identifier: GPL-2.0-or-later
// Typed errors. Every message names what was wrong in words a user can act on.
#pragma once

#include <stdexcept>
#include <string>

namespace i20 {

// What an error means for the user and the card; apps map it to an exit code in one
// place (lib/ops/outcome.hpp).
enum class ErrorKind {
  Failure,       // the card or the line failed; nothing was left half done unreported
  BadInput,      // arguments, files or values are wrong: nothing was sent
  Refused,       // a safety rule refused: nothing was written
  Uncertain,     // the card's state may differ from what was asked: the message names the cells
  FaultsRemain,  // faults stay latched after clearing
  Cancelled,     // the user interrupted, after the card was left in a known state
};

// Base of every error the toolkit raises on purpose.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message, ErrorKind kind = ErrorKind::Failure)
      : std::runtime_error(message), kind_(kind) {}
  ErrorKind kind() const noexcept { return kind_; }

 private:
  ErrorKind kind_;
};

// Bytes that break the LBP rules: impossible header, bad CRC, wrong length.
class ProtocolError : public Error {
 public:
  using Error::Error;
};

// A caller asked for something the protocol cannot express (data size 3, RPC 64, ...).
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

}  // namespace i20
