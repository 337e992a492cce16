// SPDX-License-Identifier: GPL-2.0-or-later
// Little-endian data (docs/facts.md section 1: the byte at the lower address is the LSB).
#include "lbp/bytes.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace i20::lbp;

TEST(Bytes, LittleEndianRoundTrip) {
  EXPECT_EQ(to_le(0x12345678, 4), (Bytes{0x78, 0x56, 0x34, 0x12}));
  EXPECT_EQ(read_le(Bytes{0x78, 0x56, 0x34, 0x12}), 0x12345678u);
  EXPECT_EQ(to_le(0x0102030405060708ULL, 8), (Bytes{8, 7, 6, 5, 4, 3, 2, 1}));
  EXPECT_EQ(read_le(to_le(150000, 4)), 150000u);
}

TEST(Bytes, ToLeTruncatesToTheRequestedWidth) {
  EXPECT_EQ(to_le(0x1FF, 1), (Bytes{0xFF}));
}

TEST(Bytes, HexRoundTrip) {
  EXPECT_EQ(to_hex(Bytes{0x6E, 0x10, 0x00}), "6e 10 00");
  EXPECT_EQ(from_hex("6E 10:00aa"), (Bytes{0x6E, 0x10, 0x00, 0xAA}));
  EXPECT_THROW(from_hex("6e1"), std::invalid_argument);
  EXPECT_THROW(from_hex("zz"), std::invalid_argument);
}

TEST(Bytes, HexValueIsZeroPaddedUpperCaseAndKeepsTheLowDigits) {
  EXPECT_EQ(hex_value(0x8CA0, 4), "0x8CA0");
  EXPECT_EQ(hex_value(0x12345, 8), "0x00012345");
  EXPECT_EQ(hex_value(0x5A, 2), "0x5A");
  EXPECT_EQ(hex_value(0x1FFFF, 4), "0xFFFF");  // wider values show their low word
}

// Found by the sanitizer suite: a 16-byte LBP16 read answered with append_le(value, 16)
// shifted a 64-bit value by 64 (undefined). Past 8 bytes the value is zero-extended.
TEST(Bytes, AppendLeZeroExtendsPastEightBytes) {
  i20::lbp::Bytes out;
  i20::lbp::append_le(out, 0x0807060504030201ull, 12);
  EXPECT_EQ(out, (i20::lbp::Bytes{1, 2, 3, 4, 5, 6, 7, 8, 0, 0, 0, 0}));
}
