// SPDX-License-Identifier: GPL-2.0-or-later
// The codec's own error: bytes that break the LBP rules. The toolkit's error core is
// lib/error.
#pragma once

#include "error/error.hpp"

namespace i20 {

// Bytes that break the LBP rules: impossible header, bad CRC, wrong length.
class ProtocolError : public Error {
 public:
  using Error::Error;
};

}  // namespace i20
