// SPDX-License-Identifier: GPL-2.0-or-later
// Typed errors of the profile layer. Every message is one line naming what was wrong.
#pragma once

#include <string>

#include "error/error.hpp"

namespace i20::profile {

// A profile that cannot be read or interpreted. what() is "where: key: reason [rule]",
// where `where` is "file:line" when the profile came from a file.
class ProfileError : public Error {
 public:
  ProfileError(std::string where, std::string key, std::string rule, const std::string& reason);

  const std::string& where() const { return where_; }
  const std::string& key() const { return key_; }
  const std::string& rule() const { return rule_; }
  const std::string& reason() const { return reason_; }  // without where, key and rule

 private:
  std::string where_;
  std::string key_;
  std::string rule_;
  std::string reason_;
};

// The backup file could not be written or read back; nothing was written to the card.
class BackupError : public Error {
 public:
  explicit BackupError(const std::string& message) : Error(message, ErrorKind::OutputLost) {}
};

// A tuning request that makes no physical sense (zero inductance, no bus voltage, ...).
class TuneError : public Error {
 public:
  explicit TuneError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

}  // namespace i20::profile
