// SPDX-License-Identifier: GPL-2.0-or-later
// Engineering units per the manual: 10 mV, 10 mA, 0.01 degC; values validated by range.
#include "params/value.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "params/param_db.hpp"
#include "params/text.hpp"

using namespace i20::params;

namespace {
const ParamDb& db() {
  static const ParamDb instance = ParamDb::builtin();
  return instance;
}
}  // namespace

// Raw counts, as the manual's WPD takes them ("WPD NVBRAKEONV 32000"), are written raw:N for
// a parameter with a unit; wpd itself (parse_raw) stays raw like Mesa's utility.
TEST(ParamValue, ParsesRawCountsInTheirOneRawForm) {
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "raw:32000"), 32000);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "raw:2500"), 2500);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "raw:0x9C4"), 2500);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), " raw: 750 "), 750);
  EXPECT_EQ(parse_value(db().get("NVKQP"), "raw:50"), 50) << "a unit-less parameter takes it too";
  EXPECT_EQ(parse_raw(db().get("NVBRAKEONV"), "32000"), 32000) << "wpd";
  EXPECT_EQ(parse_value(db().get("FAULTMASK"), "0xFEFF"), 0xFEFF);
  EXPECT_EQ(parse_value(db().get("FAULTMASK"), "FEFFh"), 0xFEFF);
  EXPECT_EQ(parse_value(db().get("QSETPOINT"), "-100"), -100);
}

TEST(ParamValue, ParsesEngineeringUnits) {
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "320V"), 32000);
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "320 V"), 32000);
  EXPECT_EQ(parse_value(db().get("NVBRAKEONV"), "190.5V"), 19050);
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
    // The user's units first, the card's raw counts after them.
    EXPECT_NE(msg.find("NVBRAKEONV = 390.00 V (raw 39000)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("0.00 V .. 385.00 V (raw 0..38500)"), std::string::npos) << msg;
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
    EXPECT_TRUE(refused_with("NVMAXCURRENT", text, "not a")) << text << ": " << refusal("NVMAXCURRENT", text);
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
    EXPECT_TRUE(refused_with("NVMAXCURRENT", text, ": not a number") ||
                refused_with("NVMAXCURRENT", text, ": not an integer"))
        << text << ": " << refusal("NVMAXCURRENT", text);
  EXPECT_THROW(parse_value(db().get("NVBRAKEONV"), "nan"), ValueError);
}

// Negating INT64_MIN was undefined; a number no int64 holds is out of range, with the range.
TEST(ParamValue, IntegersBeyondInt64AreOutOfRangeWithTheRange) {
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "--9223372036854775808", "not a"));
  EXPECT_EQ(refusal("NVMAXCURRENT", "raw:18446744073709551616"),
            "raw:18446744073709551616 is out of range for NVMAXCURRENT: 0.00 A .. 30.00 A (raw 0..3000)");
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "raw:9223372036854775808", "out of range for NVMAXCURRENT"));
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "raw:0x10000000000000000", "out of range for NVMAXCURRENT"));
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "18446744073709551616", "needs its unit"))
      << "bare, however large";
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
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "1e3", "needs its unit"));
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "5e", "unit 'e' is not known (a current is in A or mA)"));
}

TEST(ParamValue, DecimalCommaIsNamed) {
  EXPECT_EQ(refusal("NVMAXCURRENT", "7,5A"),
            "NVMAXCURRENT=7,5A: decimal comma: write the fraction with a point");
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

// ---- issue 20, item 3: a number without its unit is not silently raw counts ----------------

// "NVMAXCURRENT=15" planned 0.15 A; someone who meant 2000 mA and typed 2000 got 20 A.
TEST(ParamUnits, ABareNumberForAParameterWithAUnitIsRefused) {
  EXPECT_EQ(refusal("NVMAXCURRENT", "15"),
            "NVMAXCURRENT=15: a current needs its unit (15A, 15mA) or raw:15 for card counts (10 mA each)");
  EXPECT_EQ(refusal("NVBRAKEONV", "190"),
            "NVBRAKEONV=190: a voltage needs its unit (190V, 190mV) or raw:190 for card counts (10 mV each)");
  EXPECT_EQ(
      refusal("TEMPERATURE", "45"),
      "TEMPERATURE=45: a temperature needs its unit (45degC) or raw:45 for card counts (0.01 degC each)");
  EXPECT_EQ(refusal("ANGLE", "90"),
            "ANGLE=90: an angle needs its unit (90deg) or raw:90 for card counts (0.0054931640625 deg each)");
  EXPECT_EQ(refusal("NVMAXCURRENT", "7.5"), "NVMAXCURRENT=7.5: a current needs its unit (7.5A, 7.5mA)")
      << "a fraction cannot be counts: no raw: suggestion";
  EXPECT_TRUE(refused_with("NVBRAKEONV", "0x4A38", "or raw:0x4A38 for card counts"))
      << refusal("NVBRAKEONV", "0x4A38");
  EXPECT_TRUE(refused_with("NVBRAKEONV", "4A38h", "or raw:4A38h for card counts"));
  // Every parameter with a unit, whatever the number: the class, not one example.
  for (const auto& p : db().all()) {
    if (p.unit.empty()) continue;
    for (const char* text : {"0", "1", "750", "-5", "0x10", "2.5"})
      EXPECT_THROW(parse_value(p, text), MissingUnit) << p.name << "=" << text;
  }
}

TEST(ParamUnits, UnitlessParametersTakePlainNumbers) {
  EXPECT_EQ(parse_value(db().get("NVKQP"), "50"), 50);
  EXPECT_EQ(parse_value(db().get("NVKQI"), "150000"), 150000);
  EXPECT_EQ(parse_value(db().get("FAULTMASK"), "0xFEFF"), 0xFEFF);
  EXPECT_EQ(refusal("NVKQP", "5V"), "NVKQP=5V: NVKQP has no unit; give a plain whole number");
  EXPECT_EQ(refusal("NVKQP", "7.5"), "NVKQP=7.5: NVKQP takes a whole number (it has no unit)");
  for (const auto& p : db().all())
    if (p.unit.empty()) {
      EXPECT_NO_THROW(parse_value(p, "1")) << p.name;
    }
}

TEST(ParamUnits, TheRawFormIsExact) {
  EXPECT_EQ(refusal("NVMAXCURRENT", "raw:7.5"),
            "NVMAXCURRENT=raw:7.5: raw counts are a whole number, decimal or 0x hexadecimal (e.g. raw:3000)");
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "raw:", "raw counts are a whole number"));
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "raw:7.5A", "raw counts are a whole number"));
  EXPECT_TRUE(refused_with("NVMAXCURRENT", "raw:--5", "raw counts are a whole number"));
  EXPECT_EQ(refusal("NVMAXCURRENT", "RAW:750"),
            "NVMAXCURRENT=RAW:750: 'RAW:' is not known; did you mean 'raw:'?");
  EXPECT_EQ(refusal("NVMAXCURRENT", "Raw:750"),
            "NVMAXCURRENT=Raw:750: 'Raw:' is not known; did you mean 'raw:'?");
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "raw:-5"), -5) << "parsed; the range check refuses it";
  EXPECT_THROW(check_range(db().get("NVMAXCURRENT"), parse_value(db().get("NVMAXCURRENT"), "raw:-5")),
               ValueError);
}

// Today "7.5a" was accepted and "1.75mh" refused: one rule, SI case, with a did-you-mean.
TEST(ParamUnits, WrongCaseIsRefusedWithTheSymbolMeant) {
  EXPECT_EQ(refusal("NVMAXCURRENT", "7.5a"), "NVMAXCURRENT=7.5a: unit 'a' is not known; did you mean 'A'?");
  EXPECT_EQ(refusal("NVMAXCURRENT", "750ma"),
            "NVMAXCURRENT=750ma: unit 'ma' is not known; did you mean 'mA'?");
  EXPECT_EQ(refusal("NVMAXCURRENT", "750MA"),
            "NVMAXCURRENT=750MA: unit 'MA' is not known; did you mean 'mA'?")
      << "M is mega: never read as milli";
  EXPECT_EQ(refusal("NVBRAKEONV", "190v"), "NVBRAKEONV=190v: unit 'v' is not known; did you mean 'V'?");
  EXPECT_EQ(refusal("NVBRAKEONV", "190000MV"),
            "NVBRAKEONV=190000MV: unit 'MV' is not known; did you mean 'mV'?");
  EXPECT_EQ(refusal("TEMPERATURE", "45degc"),
            "TEMPERATURE=45degc: unit 'degc' is not known; did you mean 'degC'?");
  EXPECT_EQ(refusal("ANGLE", "90DEG"), "ANGLE=90DEG: unit 'DEG' is not known; did you mean 'deg'?");
  for (const char* text : {"7.5a", "7.5 a", "750Ma", "750MA"})
    EXPECT_THROW(parse_value(db().get("NVMAXCURRENT"), text), UnitError) << text;  // profiles: unit-required
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "750mA "), 75);
  EXPECT_EQ(parse_value(db().get("NVMAXCURRENT"), "7.5 A"), 750);
}

TEST(ParamUnits, AUnitOfAnotherQuantityIsNamed) {
  EXPECT_EQ(refusal("NVBRAKEONV", "3A"), "NVBRAKEONV=3A: a voltage is in V or mV, not A");
  EXPECT_EQ(refusal("NVMAXCURRENT", "12V"), "NVMAXCURRENT=12V: a current is in A or mA, not V");
  EXPECT_EQ(refusal("ANGLE", "90degC"), "ANGLE=90degC: an angle is in deg, not degC");
  EXPECT_EQ(refusal("NVMAXCURRENT", "7.5amps"),
            "NVMAXCURRENT=7.5amps: unit 'amps' is not known (a current is in A or mA)");
}

TEST(ParamUnits, OneTableForEveryParser) {
  std::string why;
  const UnitSymbol* mh = unit_of("mH", "H", why);
  ASSERT_NE(mh, nullptr);
  EXPECT_EQ(mh->power_of_ten, -3);
  EXPECT_EQ(unit_of("mh", "H", why), nullptr);
  EXPECT_EQ(why, "unit 'mh' is not known; did you mean 'mH'?");
  ASSERT_NE(unit_of("kHz", "Hz", why), nullptr);
  EXPECT_EQ(unit_of("kHz", "Hz", why)->power_of_ten, 3);
  EXPECT_EQ(unit_of("khz", "Hz", why), nullptr);
  EXPECT_EQ(why, "unit 'khz' is not known; did you mean 'kHz'?");
  EXPECT_EQ(unit_of("Ohm", "ohm", why), nullptr);
  EXPECT_EQ(why, "unit 'Ohm' is not known; did you mean 'ohm'?");
  EXPECT_EQ(symbols_text("H"), "H, mH or uH");
  EXPECT_EQ(symbols_text("ohm"), "ohm or mohm");
  // Each symbol is one spelling: no two differ only in case (the did-you-mean is unambiguous).
  const auto& table = unit_symbols();
  for (std::size_t i = 0; i < table.size(); ++i)
    for (std::size_t j = i + 1; j < table.size(); ++j)
      EXPECT_FALSE(iequals(table[i].symbol, table[j].symbol)) << table[i].symbol << " / " << table[j].symbol;
  // Every unit the database uses is in the table.
  for (const auto& p : db().all())
    if (!p.unit.empty()) {
      EXPECT_NE(unit_of(p.unit, p.unit, why), nullptr) << p.name << " " << p.unit;
    }
}
