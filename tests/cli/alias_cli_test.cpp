// SPDX-License-Identifier: GPL-2.0-or-later
// hostmot2 names on the command line (docs/facts.md s2): `i20 get nvmaxcurrent` reads
// NVMAXCURRENT and says so; a 16-bit half of a 32-bit gain is refused before anything is sent.
#include <gtest/gtest.h>

#include "harness.hpp"

using namespace i20::test;

TEST(AliasCli, GetTakesTheHostmotNameAndPrintsTheDatabaseName) {
  auto r =
      run("i20", {"--sim", "--no-user-params", "get", "nvmaxcurrent", "nvrembaudrate", "NVBUSUNDERVMIN"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("NVMAXCURRENT = "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("NVBAUDRATE = 9"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("NVBUSUNDERV = "), std::string::npos) << r.out;
  r = run("rpd", {"--sim", "--no-user-params", "nvbrakeonv"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "36000\n");
}

TEST(AliasCli, AHalfIsRefusedAndNothingIsWritten) {
  TempDir dir;
  const std::string eeprom = (dir / "card.eeprom").string();
  auto r = run("i20", {"--sim", "--sim-eeprom", eeprom, "--no-user-params", "set", "nvkqilo=5"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("use NVKQI"), std::string::npos) << r.err;
  r = run("wpd", {"--sim", "--sim-eeprom", eeprom, "--no-user-params", "nvkdihi", "3"});
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  r = run("i20", {"--sim", "--sim-eeprom", eeprom, "--no-user-params", "get", "--raw", "NVKQI", "NVKDI"});
  EXPECT_NE(r.out.find("NVKQI = 150000"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.out.find("NVKDI = 150000"), std::string::npos) << r.out << r.err;
}

// `faults decode` takes what halshow shows (hostmot2 pin names, docs/facts.md s4) and shows
// each bit's pin in the text as well as the JSON.
TEST(AliasCli, FaultsDecodeTakesAndShowsHalPins) {
  auto r = run("i20", {"faults", "decode", "hm2_7i96s.0.8i20.0.0.fault.no-enable,fault.bus-underv",
                       "--status", "status.pid-on"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("FAULT 0x0102: 2 faults set"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  LinuxCNC HAL pin: fault.no-enable\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  LinuxCNC HAL pin: fault.bus-underv\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("PIDONSTATUS (bit 9), info, HAL pin status.pid-on:"), std::string::npos) << r.out;
  r = run("i20", {"--json", "faults", "decode", "0x0200"});
  EXPECT_NE(r.out.find("\"linuxcnc_pin\": \"fault.bus-high\""), std::string::npos) << r.out;
  r = run("i20", {"faults", "decode", "status.pid-on"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("is a STATUS bit, not a FAULT bit"), std::string::npos) << r.err;
}
