// SPDX-License-Identifier: GPL-2.0-or-later
// Errors the simulator raises on purpose: bad configuration (address maps, EEPROM
// files, control lines) and host-side failures of the served streams.
#pragma once

#include "error/error.hpp"

namespace i20::sim {

// A simulator option, address map or EEPROM image is unusable.
class ConfigError : public Error {
 public:
  explicit ConfigError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

// A control line ("busv 320") could not be understood.
class ControlError : public Error {
 public:
  explicit ControlError(const std::string& message) : Error(message, ErrorKind::BadInput) {}
};

}  // namespace i20::sim
