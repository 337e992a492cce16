// SPDX-License-Identifier: GPL-2.0-or-later
// Parsing FAULT/STATUS values as users paste them.
#include <gtest/gtest.h>

#include "faults/register_value.hpp"

using namespace i20::faults;

namespace {

std::string error_of(std::string_view text) {
  try {
    parse_register_value(text, "FAULT");
  } catch (const BadRegisterValue& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& haystack, const std::string& needle) {
  return haystack.find(needle) != std::string::npos;
}

}  // namespace

TEST(FaultValue, AcceptsHexWithPrefixOrSuffix) {
  EXPECT_EQ(parse_register_value("0x0102"), 0x0102);
  EXPECT_EQ(parse_register_value("0X0102"), 0x0102);
  EXPECT_EQ(parse_register_value("0xfeff"), 0xFEFF);
  EXPECT_EQ(parse_register_value("0102h"), 0x0102);
  EXPECT_EQ(parse_register_value("FEFFH"), 0xFEFF);
  EXPECT_EQ(parse_register_value("0xFFFF"), 0xFFFF);
}

TEST(FaultValue, AcceptsDecimal) {
  EXPECT_EQ(parse_register_value("258"), 258);
  EXPECT_EQ(parse_register_value("0"), 0);
  EXPECT_EQ(parse_register_value("65535"), 65535);
  EXPECT_EQ(parse_register_value("  258\n"), 258);  // pasted with a line end
}

TEST(FaultValue, AcceptsBinaryWithOptionalGrouping) {
  EXPECT_EQ(parse_register_value("0b100000010"), 0x0102);
  EXPECT_EQ(parse_register_value("0B0000_0001_0000_0010"), 0x0102);
  EXPECT_EQ(parse_register_value("0b1111111111111111"), 0xFFFF);
}

TEST(FaultValue, RejectsGarbageSayingHowToWriteIt) {
  for (const char* bad : {"", "   ", "xyz", "0x", "0xG1", "12abc", "0b102", "0x01_", "h", "1.5", "0x-1"}) {
    const auto msg = error_of(bad);
    EXPECT_FALSE(msg.empty()) << "accepted '" << bad << "'";
    EXPECT_TRUE(contains(msg, "FAULT: ")) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_TRUE(contains(error_of("xyz"), "0x0102 or 0102h")) << error_of("xyz");
}

TEST(FaultValue, RejectsNegativeValues) {
  EXPECT_TRUE(contains(error_of("-1"), "negative")) << error_of("-1");
}

TEST(FaultValue, RejectsValuesAbove16Bits) {
  EXPECT_TRUE(contains(error_of("65536"), "does not fit the 16-bit register")) << error_of("65536");
  EXPECT_TRUE(contains(error_of("0x10000"), "at most 0xFFFF")) << error_of("0x10000");
  EXPECT_TRUE(contains(error_of("0b10000000000000000"), "does not fit"));
  EXPECT_TRUE(contains(error_of("99999999999999999999999999"), "does not fit"));
  EXPECT_TRUE(contains(error_of("0xFFFFFFFFFFFFFFFFFFFF"), "does not fit"));
}

TEST(FaultValue, A32BitPasteIsSplitAsSslbpInterface1) {
  // SSLBP Interface1: MSW = FAULT, LSW = STATUS.
  const auto msg = error_of("0x01020200");
  EXPECT_TRUE(contains(msg, "FAULT is 0x0102 and STATUS 0x0200")) << msg;
}

TEST(FaultValue, RejectsAmbiguousLeadingZeroDecimal) {
  const auto msg = error_of("0102");
  EXPECT_TRUE(contains(msg, "ambiguous")) << msg;
  EXPECT_TRUE(contains(msg, "0x0102")) << msg;
  EXPECT_EQ(parse_register_value("007"), 7);  // the same in every base
}

TEST(FaultValue, HexDigitsWithoutPrefixAskForOne) {
  const auto msg = error_of("01AB");
  EXPECT_TRUE(contains(msg, "looks like hex")) << msg;
  EXPECT_TRUE(contains(msg, "0x01AB")) << msg;
}

// The value parser's sign rule holds here too (no sign at all: registers are unsigned),
// and no spelling sneaks a sign or a second prefix past the digit check.
TEST(FaultValue, RejectsSignsInsideTheNumber) {
  for (const char* text :
       {"0x-10", "0x+10", "--5", "+-5", "+5", "0b-1", "-0x10", "0x0x10", "10-h", "nan", "inf"})
    EXPECT_FALSE(error_of(text).empty()) << text << " was accepted";
  EXPECT_TRUE(contains(error_of("--5"), "negative"));
  EXPECT_TRUE(contains(error_of("0x-10"), "not a number"));
}
