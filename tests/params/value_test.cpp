// Engineering units per the manual: 10 mV, 10 mA, 0.01 degC; values validated by range.
#include "params/value.hpp"

#include <gtest/gtest.h>

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
