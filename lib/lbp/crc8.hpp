// SPDX-License-Identifier: GPL-2.0-or-later
// Dallas/Maxim 1-Wire CRC-8 (x^8+x^5+x^4+1, reflected, init 0, no final XOR).
// The 8I20 appends it to every LBP command and every reply (manual, "CRC").
#pragma once

#include "lbp/bytes.hpp"

namespace i20::lbp {

// Incremental form, for byte streams.
class Crc8 {
 public:
  void update(Byte byte);
  void update(ByteView bytes) {
    for (Byte b : bytes) update(b);
  }
  Byte value() const { return value_; }

 private:
  Byte value_ = 0;
};

Byte crc8(ByteView bytes);

}  // namespace i20::lbp
