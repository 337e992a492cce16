// SPDX-License-Identifier: GPL-2.0-or-later
// Typed errors of the fault knowledge base. Messages are one line a user can act on.
#pragma once

#include <string>
#include <vector>

#include "error/error.hpp"

namespace i20::faults {

// params/faults.yaml (or a file given instead) is malformed. what() is "file:line: reason".
class FaultFileError : public Error {
 public:
  explicit FaultFileError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

// Text that is not a 16-bit FAULT, STATUS or FAULTMASK value.
class BadRegisterValue : public Error {
 public:
  explicit BadRegisterValue(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

// A name, slug or bit number that names no bit. what() suggests the closest slugs.
class UnknownBit : public Error {
 public:
  UnknownBit(const std::string& message, std::vector<std::string> suggestions)
      : Error(message, ErrorKind::BadInput), suggestions_(std::move(suggestions)) {}
  const std::vector<std::string>& suggestions() const { return suggestions_; }

 private:
  std::vector<std::string> suggestions_;
};

// Masking was asked for a bit the 8I20 cannot mask. what() names the bits that can be.
class NotMaskable : public Error {
 public:
  explicit NotMaskable(const std::string& message) : Error(message, ErrorKind::Refused) {}
};

}  // namespace i20::faults
