// SPDX-License-Identifier: GPL-2.0-or-later
// The parameter database against the manual's PARAMETERS table and docs/facts.md s2.
#include "params/param_db.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

using namespace i20::params;

namespace {

const ParamDb& db() {
  static const ParamDb instance = ParamDb::builtin();
  return instance;
}

std::string error_of(const std::string& yaml) {
  try {
    ParamDb::load_string(yaml, "bad.yaml");
  } catch (const ParamFileError& e) {
    return e.what();
  }
  return "";
}

// A minimal valid entry, with overridable fields.
std::string entry(const std::string& name, int address, const std::string& extra = "") {
  return "  - name: " + name + "\n    space: ram\n    address: " + std::to_string(address) +
         "\n    width: 16\n    signed: false\n    access: rw\n    description: test\n"
         "    provenance: {source: test, confirmed_on: all}\n" +
         extra;
}

}  // namespace

TEST(ParamDb, HoldsEveryParameterOfTheManualTableAndItsNvTwin) {
  // Manual "PARAMETERS": working parameters with an NV twin.
  for (const char* name : {"BRAKEOFFV", "BRAKEONV", "BUSOVERV", "BUSUNDERV", "MAXCURRENT", "DEADZONE", "KDP",
                           "KDI", "KDIL", "KQP", "KQI", "KQIL"}) {
    const Param* p = db().find(name);
    ASSERT_NE(p, nullptr) << name;
    EXPECT_EQ(p->space, Space::Ram) << name;
    const Param* nv = db().find(std::string("NV") + name);
    ASSERT_NE(nv, nullptr) << name;
    EXPECT_EQ(nv->space, Space::Eeprom);
    EXPECT_EQ(p->twin, nv->name);
    EXPECT_EQ(nv->twin, p->name);
  }
  for (const char* name : {"BUSV", "FAULT", "STATUS", "DSETPOINT", "QSETPOINT", "ANGLE", "TEMPERATURE",
                           "CLEARFAULT", "FAULTMASK", "SWREVISION", "UNITNUMBER", "NVBAUDRATE"})
    EXPECT_NE(db().find(name), nullptr) << name;
}

TEST(ParamDb, NvAddressesAreThePublicOnes) {
  // docs/facts.md section 2, table of NV byte addresses.
  const std::pair<const char*, int> expected[] = {
      {"NVMAXCURRENT", 2}, {"NVBAUDRATE", 6},  {"NVKQP", 10},      {"NVKQI", 12},
      {"NVKQIL", 16},      {"NVKDP", 18},      {"NVKDI", 20},      {"NVKDIL", 24},
      {"NVBUSUNDERV", 34}, {"NVBUSOVERV", 38}, {"NVBRAKEONV", 40}, {"NVBRAKEOFFV", 42},
  };
  for (const auto& [name, address] : expected) {
    const auto& p = db().get(name);
    ASSERT_TRUE(p.address) << name;
    EXPECT_EQ(*p.address, address) << name;
    EXPECT_TRUE(p.address_confirmed(std::nullopt)) << name << " is a public fact";
  }
  EXPECT_EQ(db().get("NVKQI").width_bits, 32u);
  EXPECT_EQ(db().get("NVKDI").width_bits, 32u);
  EXPECT_EQ(*db().get("SWREVISION").address, 2164);
  EXPECT_EQ(*db().get("UNITNUMBER").address, 2344);
  EXPECT_EQ(db().get("UNITNUMBER").width_bits, 32u);
}

TEST(ParamDb, UnitsAndScalesFollowTheManual) {
  // 10 mV, 10 mA, 0.01 degC, 65536 counts = 360 electrical degrees.
  EXPECT_EQ(db().get("NVBRAKEONV").unit, "V");
  EXPECT_DOUBLE_EQ(db().get("NVBRAKEONV").scale * 30000, 300.0);
  EXPECT_DOUBLE_EQ(db().get("BUSV").scale * 32000, 320.0);  // "RPD BUSV ... 320 V would read as 32000"
  EXPECT_EQ(db().get("MAXCURRENT").unit, "A");
  EXPECT_DOUBLE_EQ(db().get("NVMAXCURRENT").scale * 2500, 25.0);  // "WPD NVMAXCURRENT 2500 ... 25A"
  EXPECT_DOUBLE_EQ(db().get("TEMPERATURE").scale, 0.01);
  EXPECT_DOUBLE_EQ(db().get("ANGLE").scale * 65536, 360.0);
  EXPECT_TRUE(db().get("QSETPOINT").is_signed);
  EXPECT_TRUE(db().get("DSETPOINT").is_signed);
  EXPECT_EQ(db().get("NVMAXCURRENT").max, 3000);  // 30 A card rating
  EXPECT_EQ(db().get("NVBAUDRATE").max, 11);
}

TEST(ParamDb, ManualDefaultsAreRecorded) {
  EXPECT_EQ(db().get("NVKQP").default_value, 50);
  EXPECT_EQ(db().get("NVKDP").default_value, 50);
  EXPECT_EQ(db().get("NVKQI").default_value, 150000);
  EXPECT_EQ(db().get("NVKDI").default_value, 150000);
  EXPECT_EQ(db().get("NVBRAKEONV").default_value, 36000);
  EXPECT_EQ(db().get("NVBRAKEOFFV").default_value, 34000);
  EXPECT_EQ(db().get("NVBAUDRATE").default_value, 9);
}

TEST(ParamDb, ReadOnlyRegistersAreReadOnly) {
  for (const char* name : {"FAULT", "STATUS", "BUSV", "TEMPERATURE", "SWREVISION", "UNITNUMBER"})
    EXPECT_FALSE(db().get(name).writable()) << name;
  EXPECT_TRUE(db().get("CLEARFAULT").writable());
  EXPECT_FALSE(db().get("NVBAUDRATE").guard.empty());
}

TEST(ParamDb, WorkingAddressesAreConfirmedOnlyForTheSimulatorRevision) {
  ASSERT_TRUE(db().simulator_swrevision());
  const auto sim = *db().simulator_swrevision();
  for (const auto& p : db().all()) {
    if (p.space != Space::Ram || p.name == "SWREVISION" || p.name == "UNITNUMBER" || p.name == "MAXCURRENT")
      continue;
    EXPECT_FALSE(p.address_confirmed(std::nullopt)) << p.name << " must not pass for a public fact";
    EXPECT_FALSE(p.address_confirmed(0x0100)) << p.name;
    EXPECT_TRUE(p.address_confirmed(sim)) << p.name;
    EXPECT_NE(p.provenance.source.find("not publish"), std::string::npos) << p.name;
  }
  const ParamDb loaded = db();
  EXPECT_FALSE(loaded.address_confirmed(loaded.get("BRAKEONV")));
  const ParamDb resolved = loaded.for_firmware(sim);
  EXPECT_TRUE(resolved.address_confirmed(resolved.get("BRAKEONV")));
  EXPECT_FALSE(loaded.address_confirmed(loaded.get("BRAKEONV"))) << "resolving returns a new value";
}

TEST(ParamDb, MaxcurrentHasItsRealCardAddressFromLinuxCnc) {
  // docs/facts.md s2, last paragraph: LinuxCNC's hostmot2 driver reads RAM 0x08E8 of every
  // 8I20 to scale its current pin, so that address is confirmed beyond the simulator.
  const auto& p = db().get("MAXCURRENT");
  EXPECT_EQ(*p.address, 0x08E8);
  EXPECT_TRUE(p.address_confirmed(std::nullopt));
  EXPECT_TRUE(p.address_confirmed(0x0100)) << "any revision";
  EXPECT_NE(p.provenance.source.find("LinuxCNC"), std::string::npos) << p.provenance.source;
}

TEST(ParamDb, LookupIsCaseInsensitiveAndSuggestsNeighbours) {
  EXPECT_EQ(db().get("nvbrakeonv").name, "NVBRAKEONV");
  try {
    db().get("NVBRAKEON");
    FAIL() << "expected UnknownParameter";
  } catch (const UnknownParameter& e) {
    ASSERT_FALSE(e.suggestions().empty());
    EXPECT_EQ(e.suggestions().front(), "NVBRAKEONV");
    EXPECT_NE(std::string(e.what()).find("did you mean NVBRAKEONV"), std::string::npos) << e.what();
  }
  EXPECT_EQ(db().suggestions("MAXCURENT").front(), "MAXCURRENT");
  EXPECT_TRUE(db().suggestions("XYZZYPLUGH").empty());
}

TEST(ParamDb, FindsTheParameterCoveringAnAddress) {
  EXPECT_EQ(db().at_address(Space::Eeprom, 14)->name, "NVKQI");  // high word of the 32-bit NVKQI
  EXPECT_EQ(db().at_address(Space::Eeprom, 40)->name, "NVBRAKEONV");
  EXPECT_EQ(db().at_address(Space::Eeprom, 0), nullptr);
}

TEST(ParamDbLoader, RejectsUnknownKeysWithFileAndLine) {
  const auto err = error_of("schema: 1\nparameters:\n" + entry("A", 0x10, "    colour: red\n"));
  EXPECT_NE(err.find("bad.yaml:"), std::string::npos) << err;
  EXPECT_NE(err.find("unknown key 'colour'"), std::string::npos) << err;
  EXPECT_NE(err.find(":11:"), std::string::npos) << err;  // line of colour
}

TEST(ParamDbLoader, RejectsDuplicateNames) {
  const auto err = error_of("parameters:\n" + entry("A", 0x10) + entry("a", 0x20));
  EXPECT_NE(err.find("duplicate parameter name 'A'"), std::string::npos) << err;
  EXPECT_NE(err.find("bad.yaml:10"), std::string::npos) << err;
}

TEST(ParamDbLoader, RejectsOverlappingAddresses) {
  const auto err = error_of("parameters:\n" + entry("A", 0x10) + entry("B", 0x11));
  EXPECT_NE(err.find("overlaps"), std::string::npos) << err;
  // Different spaces do not overlap.
  EXPECT_EQ(error_of("parameters:\n" + entry("A", 0x10) +
                     "  - name: NVB\n    space: eeprom\n    address: 0x10\n    width: 16\n    signed: false\n"
                     "    access: rw\n    description: t\n    provenance: {source: t, confirmed_on: all}\n"),
            "");
}

TEST(ParamDbLoader, RejectsRangesThatDoNotFitTheWidth) {
  auto err = error_of("parameters:\n" + entry("A", 0x10, "    max: 70000\n"));
  EXPECT_NE(err.find("does not fit"), std::string::npos) << err;
  err = error_of("parameters:\n" + entry("A", 0x10, "    min: -1\n"));
  EXPECT_NE(err.find("does not fit"), std::string::npos) << err;
  err = error_of("parameters:\n" + entry("A", 0x10, "    min: 5\n    max: 4\n"));
  EXPECT_NE(err.find("above max"), std::string::npos) << err;
  err = error_of("parameters:\n" + entry("A", 0x10, "    default: 9\n    max: 5\n"));
  EXPECT_NE(err.find("default"), std::string::npos) << err;
}

TEST(ParamDbLoader, RejectsMissingKeysBadWidthsAndBrokenTwins) {
  EXPECT_NE(error_of("parameters:\n  - name: A\n    space: ram\n").find("lacks required key"),
            std::string::npos);
  EXPECT_NE(error_of("parameters:\n" + entry("A", 0x10, "    width: 24\n")).find("8, 16 or 32"),
            std::string::npos);
  EXPECT_NE(error_of("parameters:\n" + entry("A", 0x10, "    twin: B\n")).find("twin 'B'"),
            std::string::npos);
  EXPECT_NE(error_of("parameters:\n" + entry("A", 0x10, "    space: flash\n")).find("ram or eeprom"),
            std::string::npos);
  EXPECT_NE(error_of("parameters:\n" + entry("A", 0x1FFFF)).find("16-bit"), std::string::npos);
  EXPECT_NE(error_of("parameters: [").find("not valid YAML"), std::string::npos);
  EXPECT_NE(error_of("wibble: 1\nparameters: []\n").find("unknown key 'wibble'"), std::string::npos);
}

TEST(ParamDbOverlay, OverridesKeysAndAddsParameters) {
  ParamDb copy = db();
  copy.apply_overlay_string(
      "parameters:\n"
      "  - name: BRAKEONV\n    address: 0x0900\n"
      "    provenance: {source: discovered, confirmed_on: [0x1234]}\n" +
          entry("MYREG", 0x0A00),
      "overlay.yaml");
  EXPECT_EQ(*copy.get("BRAKEONV").address, 0x0900);
  EXPECT_EQ(copy.get("BRAKEONV").width_bits, 16u);  // untouched keys stay
  EXPECT_EQ(copy.get("BRAKEONV").provenance.source, "discovered");
  EXPECT_NE(copy.get("BRAKEONV").origin.find("overlay.yaml"), std::string::npos);
  EXPECT_NE(copy.find("MYREG"), nullptr);
  EXPECT_TRUE(copy.get("BRAKEONV").address_confirmed(0x1234));
}

TEST(ParamDbOverlay, OverlayThatCausesAnOverlapIsRejected) {
  ParamDb copy = db();
  EXPECT_THROW(copy.apply_overlay_string("parameters:\n  - name: BRAKEONV\n    address: 0x0800\n", "o.yaml"),
               ParamFileError);
}

TEST(ParamDbOverlay, RevisionSpecificOverlayWaitsForItsFirmware) {
  ParamDb copy = db();
  copy.apply_overlay_string(
      "swrevision: 0x0042\nparameters:\n  - name: KQP\n    address: 0x0A10\n"
      "    provenance: {source: map for 0x42, confirmed_on: [0x0042]}\n",
      "rev42.yaml");
  EXPECT_EQ(*copy.get("KQP").address, 0x0814);
  const ParamDb rev42 = copy.for_firmware(0x0042);
  EXPECT_EQ(*rev42.get("KQP").address, 0x0A10);
  EXPECT_TRUE(rev42.address_confirmed(rev42.get("KQP")));
  EXPECT_EQ(*copy.get("KQP").address, 0x0814) << "the loaded database stays as loaded";
  EXPECT_EQ(*copy.for_firmware(0x0043).get("KQP").address, 0x0814) << "another revision: not applied";
}

TEST(ParamDbOverlay, LoadsFromFilesAndNamesMissingOnes) {
  const auto path = std::filesystem::temp_directory_path() / "i20_overlay_test.yaml";
  std::ofstream(path) << "parameters:\n  - name: KQP\n    description: tuned\n";
  ParamDb copy = db();
  copy.apply_overlay_file(path);
  EXPECT_EQ(copy.get("KQP").description, "tuned");
  std::filesystem::remove(path);
  try {
    copy.apply_overlay_file(path);
    FAIL();
  } catch (const ParamFileError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string()), std::string::npos);
  }
}

TEST(ParamDbFile, ShippedFileEqualsTheBuiltinCopy) {
  const char* src = std::getenv("I20_SOURCE_DIR");
  ASSERT_NE(src, nullptr);
  const auto file = ParamDb::load_file(std::filesystem::path(src) / "params" / "8i20.yaml");
  ASSERT_EQ(file.all().size(), db().all().size());
  for (std::size_t i = 0; i < file.all().size(); ++i) {
    EXPECT_EQ(file.all()[i].name, db().all()[i].name);
    EXPECT_EQ(file.all()[i].address, db().all()[i].address);
  }
}
