// SPDX-License-Identifier: GPL-2.0-or-later
// Errors of the motor model: a motor file or a live setting that makes no sense.
#pragma once

#include "error/error.hpp"

namespace i20::motor {

// A motor file, a key or a value is wrong (one line: where, which key, why). Nothing changed.
class MotorError : public Error {
 public:
  explicit MotorError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

}  // namespace i20::motor
