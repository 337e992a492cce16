// SPDX-License-Identifier: GPL-2.0-or-later
// i20 info/get/set/dump/reset/ports as processes against i20sim --pty.
#include <gtest/gtest.h>

#include "harness.hpp"

using namespace i20::test;

namespace {

class I20Cli : public ::testing::Test {
 protected:
  Result i20(std::vector<std::string> args) {
    args.insert(args.begin(), {"--port", sim.port(), "--no-user-params"});
    return run("i20", args);
  }
  SimProcess sim;
};

}  // namespace

TEST_F(I20Cli, InfoShowsIdentity) {
  const auto r = i20({"info"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("8I20 on " + sim.port()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0xE120"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("unit number"), std::string::npos);
  EXPECT_NE(r.out.find("CRC errors     0"), std::string::npos) << r.out;
  const auto j = i20({"--json", "info"});
  EXPECT_NE(j.out.find("\"card_name\": \"8I20\""), std::string::npos) << j.out;
}

TEST_F(I20Cli, GetPrintsEngineeringRawAndHex) {
  auto r = i20({"get", "NVBRAKEONV", "BUSV"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "NVBRAKEONV = 360.00 V\nBUSV = 320.00 V\n");
  EXPECT_EQ(i20({"get", "--raw", "NVBRAKEONV"}).out, "NVBRAKEONV = 36000\n");
  EXPECT_EQ(i20({"get", "--hex", "NVBRAKEONV"}).out, "NVBRAKEONV = 0x8CA0\n");
  r = i20({"--json", "get", "TEMPERATURE"});
  EXPECT_NE(r.out.find("\"raw\": 3500"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"unit\": \"degC\""), std::string::npos) << r.out;
}

TEST_F(I20Cli, BitRegistersPrintInHexEverywhere) {
  sim.control("enable off");  // NOENABLEFAULT (FAULT bit 1), NOENABLESTATUS (STATUS bit 8)
  const auto r = i20({"get", "FAULT", "FAULTMASK"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "FAULT = 0x0002\nFAULTMASK = 0xFFFF\n");
  EXPECT_EQ(i20({"get", "--raw", "FAULT"}).out, "FAULT = 2\n") << "--raw stays the wire integer";
  const auto dump = i20({"dump"});
  EXPECT_NE(dump.out.find("FAULTMASK       0xFFFF"), std::string::npos) << dump.out;
  EXPECT_NE(dump.out.find("STATUS          0x0140"), std::string::npos) << dump.out;
  // The identity registers too, as `info` and every error message spell them.
  EXPECT_NE(dump.out.find("SWREVISION      0xE120"), std::string::npos) << dump.out;
  EXPECT_EQ(i20({"get", "UNITNUMBER"}).out, "UNITNUMBER = 0x00012345\n");
}

TEST_F(I20Cli, SetAcceptsUnitsAndRawAndSaysWhenAResetIsNeeded) {
  sim.control("busv 290");  // below the new 320 V brake-on and 300 V brake-off
  const auto r =
      i20({"set", "NVBRAKEONV=320V", "NVBRAKEOFFV=300V", "NVMAXCURRENT=7.5A", "BRAKEOFFV=raw:34000"});
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("NVBRAKEONV    360.00 V  320.00 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 3 values written, reset needed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Already set (not written): BRAKEOFFV 340.00 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("i20 --port " + sim.port() + " reset"), std::string::npos) << r.out;
  EXPECT_EQ(sim.control("get NVBRAKEOFFV"), "30000");
  EXPECT_EQ(i20({"get", "--raw", "NVMAXCURRENT"}).out, "NVMAXCURRENT = 750\n");
}

TEST_F(I20Cli, SetValidatesEveryValueBeforeTheFirstWrite) {
  const auto before = sim.commands_seen();
  const auto r = i20({"set", "NVBRAKEONV=320V", "NVMAXCURRENT=99A"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("NVMAXCURRENT"), std::string::npos) << r.err;
  EXPECT_EQ(sim.commands_seen(), before) << "a refused set must send nothing";
  EXPECT_EQ(i20({"get", "--raw", "NVBRAKEONV"}).out, "NVBRAKEONV = 36000\n");
}

TEST_F(I20Cli, SetRejectsBadSyntaxUnitsAndNames) {
  const auto before = sim.commands_seen();
  EXPECT_EQ(i20({"set", "NVBRAKEONV"}).exit_code, 2);
  EXPECT_EQ(i20({"set", "NVBRAKEONV=320A"}).exit_code, 2);
  EXPECT_EQ(i20({"set", "NVBRAKEONV=320.5"}).exit_code, 2);
  const auto r = i20({"set", "NVBRAKONV=320V"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("did you mean NVBRAKEONV"), std::string::npos) << r.err;
  EXPECT_EQ(sim.commands_seen(), before);
}

TEST_F(I20Cli, DumpListsEveryParameterInTableJsonAndYaml) {
  auto r = i20({"dump"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name :
       {"NVMAXCURRENT", "NVKQI", "FAULT", "STATUS", "BUSV", "KQP", "SWREVISION", "UNITNUMBER"})
    EXPECT_NE(r.out.find(name), std::string::npos) << name;
  EXPECT_NE(r.out.find("NV TWIN"), std::string::npos);
  r = i20({"dump", "--format", "json"});
  EXPECT_EQ(r.out.front(), '[');
  EXPECT_NE(r.out.find("\"name\": \"NVKQI\""), std::string::npos);
  r = i20({"dump", "--format", "yaml"});
  EXPECT_NE(r.out.find("- {name: NVKQP, raw: 50"), std::string::npos) << r.out;
}

TEST_F(I20Cli, ResetAsksAndSendsNothingWithoutConfirmation) {
  const auto before = sim.commands_seen();
  const auto r = i20({"reset"});  // stdin is not a terminal
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--yes"), std::string::npos) << r.err;
  EXPECT_EQ(sim.commands_seen(), before);
  EXPECT_EQ(i20({"reset", "--yes"}).exit_code, 0);
  EXPECT_NE(sim.trace().find("fe 5a"), std::string::npos);
}

TEST_F(I20Cli, NoTargetIsAClearError) {
  const auto r = run("i20", {"info"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--sim"), std::string::npos) << r.err;
}

TEST(I20CliSim, BuiltInSimulatorNeedsNoHardware) {
  const auto r = run("i20", {"--sim", "get", "NVKQP"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "NVKQP = 50\n");
}

TEST(I20CliSim, SimEepromPersistsBetweenRuns) {
  TempDir dir;
  const auto image = (dir / "card.eeprom").string();
  ASSERT_EQ(run("i20", {"--sim", "--sim-eeprom", image, "set", "NVBRAKEONV=370V"}).exit_code, 0);
  EXPECT_EQ(run("i20", {"--sim", "--sim-eeprom", image, "get", "NVBRAKEONV", "BRAKEONV"}).out,
            "NVBRAKEONV = 370.00 V\nBRAKEONV = 370.00 V\n")
      << "power-up loads NV into the working set";
}

TEST(I20CliDiscover, DiscoveredOverlayUnlocksWorkingWritesOnAnUnknownFirmware) {
  SimProcess sim({"--random-map", "9"});
  TempDir dir;
  const auto overlay = (dir / "map.yaml").string();
  const std::vector<std::string> target{"--port", sim.port(), "--no-user-params"};
  auto with = [&](std::vector<std::string> args) {
    args.insert(args.begin(), target.begin(), target.end());
    return args;
  };
  auto r = run("i20", with({"set", "BRAKEONV=370V"}));
  ASSERT_EQ(r.exit_code, 3) << "unknown firmware: refused until discovered: " << r.err;
  r = run("i20", with({"discover", "--yes", "--range", "0x0000-0x0FFF", "--out", overlay}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("BRAKEONV"), std::string::npos);
  EXPECT_NE(r.out.find("ambiguous"), std::string::npos) << "KQP = KDP = 50 cannot be told apart read-only";
  r = run("i20", with({"--params", overlay, "set", "BRAKEONV=370V"}));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(sim.control("get BRAKEONV"), "37000") << "the write must land at the card's own address";
  r = run("i20", with({"--params", overlay, "set", "KQP=60"}));
  EXPECT_EQ(r.exit_code, 3) << "KQP stays unknown on this firmware";
}

// Claims are computed, not constants: only the --sim endpoint is called the simulator; a
// card behind a port that reports the simulator's revision is named by that fact.
TEST_F(I20Cli, InfoNamesTheSimulatorOnlyWhereTheToolKnowsIt) {
  auto r = i20({"info"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("0xE120 (57632), the revision the simulator reports"), std::string::npos) << r.out;
  r = run("i20", {"--sim", "--no-user-params", "info"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(", the built-in simulator"), std::string::npos) << r.out;
}

// watch's and faults' JSON say which readings were not read from a confirmed address: on a
// firmware whose working map is a guess, BUSUNDERV/BUSOVERV/BRAKEONV are not facts.
TEST(I20CliClaims, ReadingsSayWhichAddressesAreNotConfirmed) {
  SimProcess sim({"--random-map", "9"});
  auto r = run("i20", {"--port", sim.port(), "--no-user-params", "--json", "faults"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"addresses_confirmed\": false"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"BUSUNDERV\""), std::string::npos) << r.out;
  SimProcess known;
  r = run("i20", {"--port", known.port(), "--no-user-params", "--json", "faults"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"addresses_confirmed\": true"), std::string::npos) << r.out;
}
