// SPDX-License-Identifier: GPL-2.0-or-later
// The register map: the built-in one matches params/8i20.yaml, overrides and shuffles
// move working parameters, and the card then really lives at the new addresses.
#include "bench.hpp"
#include "params/param_db.hpp"
#include "sim/error.hpp"
#include "sim/param_map.hpp"

namespace i20::sim::test {
namespace {

TEST(SimMap, BuiltinMatchesTheParameterDatabase) {
  const auto from_yaml = register_map_from(params::ParamDb::builtin());
  const auto builtin = RegisterMap::builtin();
  EXPECT_EQ(from_yaml.swrevision(), kBuiltinSwRevision);
  EXPECT_EQ(from_yaml.all().size(), builtin.all().size());
  for (const auto& r : builtin.all()) {
    const auto* y = from_yaml.find(r.name);
    ASSERT_NE(y, nullptr) << r.name;
    EXPECT_EQ(y->space, r.space) << r.name;
    EXPECT_EQ(y->address, r.address) << r.name;
    EXPECT_EQ(y->width_bits, r.width_bits) << r.name;
    EXPECT_EQ(y->is_signed, r.is_signed) << r.name;
    EXPECT_EQ(y->read_only, r.read_only) << r.name;
    EXPECT_EQ(y->twin, r.twin) << r.name;
    EXPECT_EQ(y->default_value, r.default_value) << r.name;
  }
}

TEST(SimMap, DefaultsTheYamlLeavesOpen) {
  const auto m = RegisterMap::builtin();
  EXPECT_EQ(m.at("NVMAXCURRENT").default_value, 1000);  // 10 A
  EXPECT_EQ(m.at("NVBRAKEONV").default_value, 36000);
  EXPECT_EQ(m.at("FAULTMASK").default_value, 0xFFFF);
}

TEST(SimMap, OverridesMoveParametersAndTheRevision) {
  const auto m = RegisterMap::with_overrides_text(RegisterMap::builtin(),
                                                  "# moved\nFAULT = 0x0900\nstatus = 2306  # decimal\n"
                                                  "revision = 0xE121\n",
                                                  "test.map");
  EXPECT_EQ(m.at("FAULT").address, 0x0900);
  EXPECT_EQ(m.at("STATUS").address, 2306);
  EXPECT_EQ(m.swrevision(), 0xE121);
  DeviceOptions o;
  o.map = m;
  o.world.enable = false;
  Bench b(o);
  EXPECT_EQ(b.read(0x0900), 0x0002u) << "FAULT (no enable) at its new address";
  EXPECT_EQ(b.read(2164), 0xE121u);
  EXPECT_EQ(b.write16(0x0900, 0), lbp::Bytes{0x00});
  EXPECT_TRUE(b.local(0xC1) & lbp::local::kStatusInvalidWrite) << "read-only at the new address";
}

TEST(SimMap, BadOverridesAreReportedWithTheirLine) {
  const auto base = RegisterMap::builtin();
  try {
    RegisterMap::with_overrides_text(base, "FAULT = 0x0900\nNOSUCH = 3\n", "bad.map");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("NOSUCH"), std::string::npos);
  }
  try {
    RegisterMap::with_overrides_text(base, "FAULT 0x0900\n", "bad.map");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.map:1"), std::string::npos);
  }
  EXPECT_THROW(RegisterMap::with_overrides_text(base, "FAULT = 0x0802\n", "x"), ConfigError)
      << "overlaps STATUS";
  EXPECT_THROW(RegisterMap::with_overrides_text(base, "FAULT = 0x10000\n", "x"), ConfigError);
  EXPECT_THROW(RegisterMap::with_overrides(base, "/nonexistent/i20.map"), ConfigError);
}

TEST(SimMap, ShuffleIsDeterministicAndKeepsPublicAddresses) {
  const auto base = RegisterMap::builtin();
  const auto a = base.shuffled(7), again = base.shuffled(7), other = base.shuffled(8);
  EXPECT_NE(a.swrevision(), kBuiltinSwRevision);
  unsigned moved = 0, differs = 0;
  for (const auto& r : base.all()) {
    const auto& x = a.at(r.name);
    EXPECT_EQ(x.address, again.at(r.name).address) << r.name;
    if (r.space == Space::Eeprom || r.name == "SWREVISION" || r.name == "UNITNUMBER" ||
        r.name == "MAXCURRENT")
      EXPECT_EQ(x.address, r.address) << r.name << " is public and must stay";
    else
      EXPECT_EQ(x.address % 2, 0) << r.name;
    moved += x.address != r.address;
    differs += x.address != other.at(r.name).address;
  }
  EXPECT_GT(moved, 10u);
  EXPECT_GT(differs, 10u);
  EXPECT_NO_THROW(a.validate());
}

TEST(SimMap, MaxcurrentSitsWhereLinuxCncReadsItOnEveryCard) {
  // LinuxCNC's hostmot2 driver reads RAM 0x08E8 of every 8I20 to scale its current pin
  // (docs/facts.md s2): the database and the simulator built from it agree, shuffled too.
  const auto yaml = register_map_from(params::ParamDb::builtin());
  EXPECT_EQ(yaml.at("MAXCURRENT").address, 0x08E8);
  EXPECT_EQ(RegisterMap::builtin().at("MAXCURRENT").address, 0x08E8);
  for (std::uint64_t seed : {1u, 5u, 7u, 42u})
    EXPECT_EQ(yaml.shuffled(seed).at("MAXCURRENT").address, 0x08E8);
  Bench b;
  EXPECT_EQ(b.read(0x08E8), 1000u) << "MAXCURRENT = NVMAXCURRENT after power-up";
}

TEST(SimMap, ShuffledCardBehavesAtItsOwnAddresses) {
  DeviceOptions o;
  o.map = RegisterMap::builtin().shuffled(3);
  Bench b(o);
  const auto& m = b.card.amplifier().map();
  // After power-up each working twin equals its NV value, wherever it lives (docs/facts.md s3).
  EXPECT_EQ(b.read(m.at("BRAKEONV").address), 36000u);
  EXPECT_EQ(b.read(m.at("KQI").address, 4), 150000u);
  EXPECT_EQ(b.read(m.at("BUSV").address), 32000u);
  EXPECT_EQ(b.read(2164), m.swrevision());
  if (m.at("FAULT").address != 0x0800) {
    b.write16(0x0800, 0x1234);
    EXPECT_EQ(b.local(0xC1) & lbp::local::kStatusInvalidWrite, 0) << "0x0800 is plain RAM here";
  }
}

}  // namespace
}  // namespace i20::sim::test
