// SPDX-License-Identifier: GPL-2.0-or-later
// CRC-8 vectors: manual "CRC" (Dallas/Maxim polynomial x^8+x^5+x^4+1) and docs/facts.md section 1.
#include "lbp/crc8.hpp"

#include <gtest/gtest.h>

#include <string_view>

using namespace i20::lbp;

namespace {
Bytes ascii(std::string_view s) {
  return Bytes(s.begin(), s.end());
}
}  // namespace

TEST(Crc8, CheckValueOf123456789IsA1) {
  EXPECT_EQ(crc8(ascii("123456789")), 0xA1);
}

TEST(Crc8, EmptyDataGivesZeroSoDatalessRepliesAreASingle00) {
  EXPECT_EQ(crc8({}), 0x00);
}

TEST(Crc8, KnownOneWireVectors) {
  // Maxim application note 27: ROM code 02 1C B8 01 00 00 00 has CRC A2.
  EXPECT_EQ(crc8(Bytes{0x02, 0x1C, 0xB8, 0x01, 0x00, 0x00, 0x00}), 0xA2);
  // Single bytes exercise the reflected polynomial 0x8C.
  EXPECT_EQ(crc8(Bytes{0x01}), 0x5E);
  EXPECT_EQ(crc8(Bytes{0x80}), 0x8C);
}

TEST(Crc8, AppendingTheCrcMakesTheRemainderZero) {
  Bytes data = ascii("8I20 LBP");
  data.push_back(crc8(data));
  EXPECT_EQ(crc8(data), 0x00);
}

TEST(Crc8, IncrementalMatchesOneShot) {
  const auto data = ascii("123456789");
  Crc8 crc;
  for (Byte b : data) crc.update(b);
  EXPECT_EQ(crc.value(), crc8(data));
}

TEST(Crc8, DetectsEverySingleBitFlip) {
  const auto data = ascii("123456789");
  for (std::size_t i = 0; i < data.size(); ++i)
    for (int bit = 0; bit < 8; ++bit) {
      auto flipped = data;
      flipped[i] ^= static_cast<Byte>(1 << bit);
      EXPECT_NE(crc8(flipped), 0xA1) << "byte " << i << " bit " << bit;
    }
}
