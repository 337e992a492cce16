// SPDX-License-Identifier: GPL-2.0-or-later
// Engineering units per the manual: 10 mV, 10 mA, 0.01 degC; values validated by range.
#include "params/value.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "params/param_db.hpp"

using namespace i20::params;

namespace {
const ParamDb& db() {
  static const ParamDb instance = ParamDb::builtin();
  return instance;
}
}  // namespace

TEST(ParamValue, ParsesRawIntegersLikeWpd) {
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "32000"), 32000);  // "WPD NVBRAKEONV 32000"
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "2500"), 2500);
  EXPECT_EQ(parse_value(db().get("FAULTMASK"), "0xFEFF"), 0xFEFF);
  EXPECT_EQ(parse_value(db().get("FAULTMASK"), "FEFFh"), 0xFEFF);
  EXPECT_EQ(parse_value(db().get("QSETPOINT"), "-100"), -100);
}

TEST(ParamValue, ParsesEngineeringUnits) {
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "320V"), 32000);
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "320 V"), 32000);
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "190.5v"), 19050);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "7.5A"), 750);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "750mA"), 75);
  EXPECT_EQ(parse_value(db().get("ANGLE"), "180deg"), 32768);
}

TEST(ParamValue, RefusesAmbiguousOrWrongUnits) {
  EXPECT_THROW(parse_value(db().get("NVBRAKEONV"), "320.5"), ValueError);  // fraction without unit
  EXPECT_THROW(parse_value(db().get("NVBRAKEONV"), "3A"), ValueError);
  EXPECT_THROW(parse_value(db().get("NVMAXCURRENT"), "7.555A"), ValueError);  // finer than 10 mA
  EXPECT_THROW(parse_value(db().get("NVKQP"), "5V"), ValueError);
  EXPECT_THROW(parse_value(db().get("NVKQP"), "lots"), ValueError);
  EXPECT_THROW(parse_raw(db().get("NVKQP"), "7.5"), ValueError);
  try {
    parse_value(db().get("NVMAXCURRENT"), "7.5");
    FAIL();
  } catch (const ValueError& e) {
    EXPECT_NE(std::string(e.what()).find("7.5A"), std::string::npos) << e.what();
  }
}

TEST(ParamValue, RangeCheckNamesTheLimitsInUnits) {
  const auto& onv = db().get("NVBRAKEONV");
  EXPECT_NO_THROW(check_range(onv, 38500));
  try {
    check_range(onv, 39000);
    FAIL();
  } catch (const ValueError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("NVBRAKEONV = 39000 (390.00 V)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("385.00 V"), std::string::npos) << msg;
  }
  EXPECT_THROW(check_range(db().get("NVMAXCURRENT"), 3001), ValueError);
  EXPECT_THROW(check_range(db().get("NVMAXCURRENT"), -1), ValueError);
  EXPECT_THROW(check_range(db().get("NVBAUDRATE"), 12), ValueError);
  EXPECT_THROW(check_range(db().get("FAULTMASK"), 0xFF00), ValueError);  // only bit 8 may be masked
  EXPECT_NO_THROW(check_range(db().get("FAULTMASK"), 0xFEFF));
}

TEST(ParamValue, FormatsWithTheScaleResolution) {
  EXPECT_EQ(format_engineering(db().get("NVBRAKEONV"), 36000), "360.00 V");
  EXPECT_EQ(format_engineering(db().get("NVMAXCURRENT"), 750), "7.50 A");
  EXPECT_EQ(format_engineering(db().get("TEMPERATURE"), 4512), "45.12 degC");
  EXPECT_EQ(format_engineering(db().get("NVKQI"), 150000), "150000");
}

TEST(ParamValue, WireBytesAreLittleEndianAndSignExtended) {
  const auto& q = db().get("QSETPOINT");
  EXPECT_EQ(raw_from_bytes(q, i20::lbp::Bytes{0xFF, 0xFF}), -1);
  EXPECT_EQ(bytes_from_raw(q, -2), (i20::lbp::Bytes{0xFE, 0xFF}));
  const auto& kqi = db().get("NVKQI");
  EXPECT_EQ(raw_from_bytes(kqi, bytes_from_raw(kqi, 150000)), 150000);
  EXPECT_EQ(bytes_from_raw(kqi, 150000), (i20::lbp::Bytes{0xF0, 0x49, 0x02, 0x00}));
  EXPECT_EQ(raw_from_bytes(db().get("NVBRAKEONV"), i20::lbp::Bytes{0xA0, 0x8C}), 36000);
}

// ---- The number syntax, hardened (fuzz/regressions/value_parse) ----------------------------

namespace {
std::string refusal(const char* name, const std::string& text) {
  try {
    const auto v = parse_value(db().get(name), text);
    return "(accepted as " + std::to_string(v) + ")";
  } catch (const ValueError& e) {
    return e.what();
  }
}
bool refused_with(const char* name, const std::string& text, const std::string& words) {
  return refusal(name, text).find(words) != std::string::npos;
}
}  // namespace

// from_chars after a sign took a second sign: "--5" was -(-5) = 5, "0x-10" was -16.
TEST(ParamValue, ExactlyOneOptionalSign) {
  for (const char* text : {"--5", "--1000", "-+5", "+-5", "++5", "0x-10", "-0x-10", "-0x-3E8", "0x+10", "- 5",
                           "-", "+", "0x", "-h"})
    EXPECT_TRUE(refused_with("NVMAXCURRENT", text, "is not a"))
        << text << ": " << refusal("NVMAXCURRENT", text);
  EXPECT_THROW(parse_raw(db().get("NVMAXCURRENT"), "--1000"), ValueError);
  EXPECT_THROW(parse_raw(db().get("NVMAXCURRENT"), "-0x-3E8"), ValueError);
  EXPECT_EQ(parse_value(db().get("QSETPOINT"), "+5"), 5);
  EXPECT_EQ(parse_value(db().get("QSETPOINT"), "-0x10"), -16);
  EXPECT_EQ(parse_value(db().get("QSETPOINT"), "-10h"), -16);
}

// "nanA" became a NaN converted to int64; strtod also took "inf", "infinity" and hex floats.
TEST(ParamValue, NoNanInfinityOrHexFractions) {
  for (const char* text :
       {"nanA", "nan A", "NaN A", "-nanA", "infA", "inf A", "infinityA", "0x1p3A", "0x1.8p1 A"})
    EXPECT_TRUE(refused_with("NVMAXCURRENT", text, "is not a number") ||
                refused_with("NVMAXCURRENT", text, "is not an integer"))
        << text << ": " << refusal("NVMAXCURRENT", text);
  EXPECT_THROW(parse_value(db().get("NVBRAKEONV"), "nan"), ValueError);
}

// Negating INT64_MIN was undefined; a number no int64 holds is out of range, with the range.
TEST(ParamValue, IntegersBeyondInt64AreOutOfRangeWithTheRange) {
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "--9223372036854775808", "is not a"));
  EXPECT_EQ(refusal("NVMAXCURRENT", "18446744073709551616"),
            "18446744073709551616 is out of range for NVMAXCURRENT (0..3000 = 0.00 A .. 30.00 A)");
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "9223372036854775808", "out of range for NVMAXCURRENT"));
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "0x10000000000000000", "out of range for NVMAXCURRENT"));
  EXPECT_TRUE(refused_with("NVKQP", "-9223372036854775809", "out of range for NVKQP"));
  EXPECT_EQ(parse_raw(db().get("NVKQP"), "-9223372036854775808"), std::numeric_limits<std::int64_t>::min())
      << "the most negative int64 parses (the range check refuses it later)";
  EXPECT_EQ(parse_raw(db().get("NVKQP"), "9223372036854775807"), std::numeric_limits<std::int64_t>::max());
  EXPECT_THROW(check_range(db().get("NVKQP"), std::numeric_limits<std::int64_t>::min()), ValueError);
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "1e300A", "out of range for NVMAXCURRENT"));
}

// The value must be an exact multiple of the resolution, however small the remainder:
// 1e-20 A used to round to 0 counts and be written as 0 A.
TEST(ParamValue, FinerThanTheResolutionIsRefusedOnEveryPath) {
  for (const char* text :
       {"1e-20A", "1e-400A", "0.001A", "7.555A", "0.5mA", "3000.0000000000001A", "1e-20 mA"})
    EXPECT_TRUE(refused_with("NVMAXCURRENT", text, "finer than its resolution of 0.01 A"))
        << text << ": " << refusal("NVMAXCURRENT", text);
  EXPECT_TRUE(refused_with("ANGLE", "1deg", "finer than its resolution")) << "360/65536 degrees per count";
  EXPECT_EQ(parse_value(db().get("ANGLE"), "0.0054931640625deg"), 1) << "exactly one count";
  EXPECT_EQ(parse_value(db().get("ANGLE"), "-90deg"), -16384);
}

TEST(ParamValue, ExponentsAndZerosMeanWhatTheySay) {
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "1.9e2V"), 19000);
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "19000e-2 V"), 19000);
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "190000mV"), 19000);
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), ".5V"), 50);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "0.000A"), 0);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "-0A"), 0);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "0e999999999A"), 0);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "7.50000000000000000000000000A"), 750);
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "1e3", "is not a raw integer and has no unit"));
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "5e", "is in A, not 'e'"));
}

TEST(ParamValue, DecimalCommaIsNamed) {
  EXPECT_EQ(refusal("NVMAXCURRENT", "7,5A"),
            "NVMAXCURRENT: '7,5A' has a decimal comma; write the fraction with a point");
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "7,5 A", "decimal comma"));
}

TEST(ParamValue, ScanIntegerIsTheLoadersSyntaxToo) {
  EXPECT_EQ(scan_integer("0x7D00").value, 0x7D00);
  EXPECT_EQ(scan_integer("7D00h").value, 0x7D00);
  EXPECT_EQ(scan_integer("7D00h", /*hex_suffix=*/false).status, IntegerText::Status::NotInteger);
  EXPECT_EQ(scan_integer("--5").status, IntegerText::Status::NotInteger);
  EXPECT_EQ(scan_integer("99999999999999999999").status, IntegerText::Status::OutOfRange);
  EXPECT_EQ(scan_integer(" 5").status, IntegerText::Status::NotInteger) << "callers trim";
}
