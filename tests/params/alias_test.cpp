// SPDX-License-Identifier: GPL-2.0-or-later
// LinuxCNC's hostmot2 names as aliases (params/8i20.yaml `aliases:`; docs/facts.md s2):
// accepted wherever a name is, case-insensitively; a 16-bit half of a 32-bit value is
// recognised and refused, naming the whole parameter; the loader keeps names unambiguous.
#include <gtest/gtest.h>

#include "params/param_db.hpp"

using namespace i20::params;

namespace {

const ParamDb& db() {
  static const ParamDb instance = ParamDb::builtin();
  return instance;
}

std::string entry(const std::string& name, int address, const std::string& extra, int width = 16) {
  return "  - name: " + name + "\n    space: eeprom\n    address: " + std::to_string(address) +
         "\n    width: " + std::to_string(width) +
         "\n    signed: false\n    access: rw\n    description: test\n"
         "    provenance: {source: test, confirmed_on: all}\n" +
         extra;
}

std::string error_of(const std::string& entries) {
  try {
    ParamDb::load_string("schema: 1\nparameters:\n" + entries, "bad.yaml");
  } catch (const ParamFileError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ParamAlias, EveryHostmotNameFindsItsParameter) {
  // sserial.h hm2_8i20_globals: the driver's name -> the manual's parameter.
  const std::pair<const char*, const char*> names[] = {{"nvmaxcurrent", "NVMAXCURRENT"},
                                                       {"nvrembaudrate", "NVBAUDRATE"},
                                                       {"nvkqp", "NVKQP"},
                                                       {"nvkqil", "NVKQIL"},
                                                       {"nvkdp", "NVKDP"},
                                                       {"nvkdil", "NVKDIL"},
                                                       {"nvbusundervmin", "NVBUSUNDERV"},
                                                       {"nvbusundervmax", "NVBUSUNDERVMAX"},
                                                       {"nvbusoverv", "NVBUSOVERV"},
                                                       {"nvbrakeonv", "NVBRAKEONV"},
                                                       {"nvbrakeoffv", "NVBRAKEOFFV"}};
  for (const auto& [alias, name] : names) {
    ASSERT_NE(db().find(alias), nullptr) << alias;
    EXPECT_EQ(db().get(alias).name, name) << alias;
    EXPECT_EQ(db().get(std::string(alias) == "nvrembaudrate" ? "NvRemBaudRate" : alias).name, name);
  }
}

TEST(ParamAlias, AHalfOfAThirtyTwoBitGainIsRefusedNamingTheWholeValue) {
  for (const char* half : {"nvkqilo", "nvkqihi", "nvkdilo", "NVKDIHI"}) {
    EXPECT_EQ(db().find(half), nullptr) << half << " must not resolve to the 32-bit value";
    try {
      (void)db().get(half);
      FAIL() << half;
    } catch (const HalfAlias& e) {
      const std::string what = e.what();
      const std::string whole = std::string(half).find("kq") != std::string::npos ||
                                        std::string(half).find("KQ") != std::string::npos
                                    ? "NVKQI"
                                    : "NVKDI";
      EXPECT_NE(what.find("use " + whole), std::string::npos) << what;
      EXPECT_NE(what.find("& 0xFFFF"), std::string::npos) << what;
      EXPECT_EQ(e.kind(), i20::ErrorKind::BadInput);
    }
    EXPECT_EQ(db().suggestions(half).front(),
              std::string(half).find("kq") != std::string::npos ? "NVKQI" : "NVKDI");
  }
  const auto a = db().alias("nvkqihi");
  ASSERT_NE(a.alias, nullptr);
  EXPECT_EQ(a.param->name, "NVKQI");
  EXPECT_EQ(a.alias->part, Alias::Part::High16);
}

TEST(ParamAlias, TheLoaderKeepsNamesUnambiguous) {
  EXPECT_EQ(error_of(entry("A", 2, "    aliases: [nva]\n") + entry("B", 4, "    aliases: [NVA]\n")),
            "bad.yaml:3: A: alias 'nva' is also an alias of B (bad.yaml:12)");
  EXPECT_EQ(error_of(entry("A", 2, "    aliases: [b]\n") + entry("B", 4, "")),
            "bad.yaml:3: A: alias 'b' is the name of B");
  EXPECT_EQ(error_of(entry("A", 2, "    aliases: [{name: alo, bits: 0-15}]\n")),
            "bad.yaml:3: A: alias 'alo' names a 16-bit half, but A is not 32 bit");
  EXPECT_NE(
      error_of(entry("A", 2, "    aliases: [{name: alo, bits: 0-7}]\n", 32)).find("must be 0-15 or 16-31"),
      std::string::npos);
  EXPECT_NE(error_of(entry("A", 2, "    aliases: [\"two words\"]\n")).find("must be one word"),
            std::string::npos);
  EXPECT_NE(error_of(entry("A", 2, "    aliases: nva\n")).find("'aliases' must be a list"),
            std::string::npos);
  // Its own name in another case only records the hostmot2 spelling.
  EXPECT_EQ(error_of(entry("A", 2, "    aliases: [a]\n")), "");
}
