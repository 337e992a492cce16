// SPDX-License-Identifier: GPL-2.0-or-later
// wpd/rpd as drop-ins for Mesa's WPD/RPD (manual, "DRIVE PARAMETER SETUP"), run as
// processes against i20sim --pty, including every refusal and proof that it sent nothing.
#include <gtest/gtest.h>

#include "harness.hpp"

using namespace i20::test;

namespace {

class LegacyTools : public ::testing::Test {
 protected:
  std::map<std::string, std::string> env() const {
    return {{"COMPORT", sim.port()},
            {"BAUDRATE", "115200"},
            {"PROTOCOL", "LBP"},
            {"I20_PARAMS", ""},
            {"XDG_CONFIG_HOME", "/nonexistent"}};
  }
  Result rpd(const std::vector<std::string>& args) { return run("rpd", args, env()); }
  Result wpd(const std::vector<std::string>& args) { return run("wpd", args, env()); }
  SimProcess sim;
};

}  // namespace

TEST_F(LegacyTools, RpdReadsBusVoltageIn10mVUnits) {
  sim.control("busv 320");
  const auto r = rpd({"BUSV"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "32000\n");  // manual: "a bus voltage of 320 would read as 32000"
}

TEST_F(LegacyTools, RpdHPrintsAHexadecimalWord) {
  sim.control("enable off");  // NOENABLEFAULT, bit 1
  const auto r = rpd({"FAULT", "H"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "0002\n");
}

TEST_F(LegacyTools, WpdNvWriteIsVerifiedAndOnlyLiveAfterReset) {
  auto r = wpd({"NVMAXCURRENT", "2500"});  // manual: 25 A, "will not take effect until the 8I20 is reset"
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("25.00 A"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("after the 8I20 is reset"), std::string::npos) << r.out;
  EXPECT_EQ(rpd({"NVMAXCURRENT"}).out, "2500\n");
  EXPECT_EQ(rpd({"MAXCURRENT"}).out, "1000\n") << "an NV write must change nothing live";
  EXPECT_EQ(sim.control("get MAXCURRENT"), "1000");
  ASSERT_EQ(run("i20", {"--port", sim.port(), "reset", "--yes"}, env()).exit_code, 0);
  EXPECT_EQ(rpd({"MAXCURRENT"}).out, "2500\n");
}

TEST_F(LegacyTools, WpdWorkingWriteIsLive) {
  sim.control("busv 160");  // a 120 V line: a 300 V brake-on is safe there
  // The manual's rule first: BrakeOn always higher than BrakeOff (340 V on a factory card).
  ASSERT_EQ(wpd({"BRAKEOFFV", "28000"}).exit_code, 0);
  const auto r = wpd({"BRAKEONV", "30000"});  // manual: 300 V
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(sim.control("get BRAKEONV"), "30000");
}

TEST_F(LegacyTools, WpdRefusesAnOverVoltageAtOrBelowTheMeasuredBus) {
  sim.control("busv 320");  // a live BUSOVERV of 300 V would fault the drive at once
  const auto r = wpd({"BUSOVERV", "30000"});
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.err.find("320.00 V the card measures"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(sim.writes_seen(), 0u) << sim.trace();
  EXPECT_EQ(sim.control("get BUSOVERV"), "38500");
}

TEST_F(LegacyTools, OutOfRangeIsRefusedAndNothingIsSent) {
  const auto before = sim.commands_seen();
  const auto r = wpd({"NVMAXCURRENT", "3001"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("outside its valid range"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "one line: " << r.err;
  EXPECT_EQ(sim.commands_seen(), before) << sim.trace();
}

TEST_F(LegacyTools, ReadOnlyAndGuardedWritesAreRefusedAndNothingIsSent) {
  const auto before = sim.commands_seen();
  auto r = wpd({"BUSV", "100"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("read-only"), std::string::npos) << r.err;
  r = wpd({"NVBAUDRATE", "4"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("link speed"), std::string::npos) << r.err;
  EXPECT_EQ(sim.commands_seen(), before);
  r = wpd({"--force", "NVBAUDRATE", "4"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(rpd({"NVBAUDRATE"}).out, "4\n");
}

TEST_F(LegacyTools, BadValuesAndNamesAreOneLineErrors) {
  auto r = wpd({"NVMAXCURRENT", "lots"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not an integer"), std::string::npos) << r.err;
  r = rpd({"NVBRAKEON"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("did you mean NVBRAKEONV"), std::string::npos) << r.err;
  EXPECT_EQ(sim.writes_seen(), 0u);
}

TEST_F(LegacyTools, EnvironmentIsCheckedLikeWpd) {
  auto e = env();
  e["PROTOCOL"] = "SSLBP";
  auto r = run("rpd", {"BUSV"}, e);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("PROTOCOL=LBP"), std::string::npos) << r.err;
  e = env();
  e["COMPORT"] = "";
  r = run("rpd", {"BUSV"}, e);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("COMPORT"), std::string::npos) << r.err;
  // --port wins over COMPORT.
  e = env();
  e["COMPORT"] = "/dev/nonexistent-port";
  r = run("rpd", {"--port", sim.port(), "BUSV"}, e);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = run("rpd", {"BUSV"}, e);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("/dev/nonexistent-port"), std::string::npos) << r.err;
}

TEST_F(LegacyTools, WpdFault0ClearsThroughClearfault) {
  sim.control("enable off");
  auto r = wpd({"FAULT", "0"});
  EXPECT_EQ(r.exit_code, 5) << "the cause (no enable) is still present: " << r.out << r.err;
  sim.control("enable on");
  r = wpd({"FAULT", "0"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(rpd({"FAULT"}).out, "0\n");
}

TEST(LegacyToolsUnconfirmed, WorkingWritesOnAnUnknownFirmwareNeedAllowUnverified) {
  SimProcess sim({"--random-map", "7"});  // another SWREVISION: the database map is a guess there
  const std::map<std::string, std::string> env{{"COMPORT", sim.port()}, {"I20_PARAMS", ""}};
  auto r = run("wpd", {"BRAKEONV", "30000"}, env);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("not confirmed"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pass --allow-unverified"), std::string::npos) << "wpd has the option: " << r.err;
  EXPECT_EQ(sim.trace().find(": 6"), std::string::npos) << "no write may reach the card:\n" << sim.trace();
  r = run("i20", {"set", "BRAKEONV=300V"}, env);
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.err.find("pass --allow-unverified"), std::string::npos) << "i20 set has the option: " << r.err;
  EXPECT_EQ(sim.trace().find(": 6"), std::string::npos) << "no write may reach the card:\n" << sim.trace();
  // NV addresses are public: they work on any firmware at once.
  r = run("wpd", {"NVBRAKEONV", "37000"}, env);
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A card that stops answering after N commands: during identification (RPC memory mode on
// to read the RPC table), inside NV access mode, and later. The tool never ends with the
// card still in either mode unsaid: then it exits 4 and names the mode and the way back,
// once (i20 said it three times: in the outcome, and twice more from its final settle).
// The N were read off the simulator's trace (rpd: RPC memory at commands 17-26, NV access
// at 27-30; wpd and i20 set the same, then NV access again around the write).
TEST(ToolsMute, AModeLeftOnIsSaidOnceByEveryProgram) {
  for (const char* program : {"rpd", "wpd", "i20"}) {
    int left_on = 0;
    for (int n : {18, 28, 29, 30, 45}) {
      SCOPED_TRACE(std::string(program) + " mute-after " + std::to_string(n));
      SimProcess sim({"--busv", "160"});
      sim.control("mute-after " + std::to_string(n));
      const std::string p = program;
      const std::vector<std::string> args = p == "rpd" ? std::vector<std::string>{"NVMAXCURRENT"}
                                            : p == "wpd"
                                                ? std::vector<std::string>{"NVMAXCURRENT", "1200"}
                                                : std::vector<std::string>{"set", "NVMAXCURRENT=12A"};
      const auto r = run(program, args,
                         {{"COMPORT", sim.port()},
                          {"I20_PARAMS", ""},
                          {"XDG_CONFIG_HOME", "/nonexistent"},
                          {"XDG_STATE_HOME", "/tmp"}});
      sim.control("mute-after off");
      const auto state = sim.control("show");
      const bool nv_on = state.find("nv_access=eeprom") != std::string::npos;
      const bool rpc_on = state.find("rpcmem=on") != std::string::npos;
      if (nv_on || rpc_on) {
        ++left_on;
        EXPECT_EQ(r.exit_code, 4) << r.err;
        EXPECT_NE(r.err.find(nv_on ? "NV (EEPROM) access mode and may still be in it" : "may still be in it"),
                  std::string::npos)
            << r.err;
        const auto said = r.err.find("may still be in it");
        EXPECT_EQ(r.err.find("may still be in it", said + 1), std::string::npos) << "said more than once:\n"
                                                                                 << r.err;
      }
    }
    EXPECT_GT(left_on, 0) << program << ": no mute landed inside a mode; the test proves nothing";
  }
}

// COMPORT names the card for every i20 command given no target (ops::Session), the profile
// commands included: they once opened cards themselves and ignored it.
TEST_F(LegacyTools, ProfileCommandsFindTheCardThroughComportAsEveryI20CommandDoes) {
  auto r = run("i20", {"profile", "diff", "line-120v"}, env());
  EXPECT_EQ(r.exit_code, 1) << "the card differs from a 120 V profile, as diff(1): " << r.out << r.err;
  EXPECT_NE(r.out.find("against 8I20"), std::string::npos) << r.out;
  TempDir dir;
  const auto saved = (dir / "saved.yaml").string();
  r = run("i20", {"profile", "save", saved}, env());
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  r = run("i20", {"profile", "diff", saved}, env());
  EXPECT_EQ(r.exit_code, 0) << "the card holds what was saved from it: " << r.out << r.err;
  const auto writes = sim.writes_seen();
  r = run("i20", {"profile", "validate", "line-120v"}, env());
  EXPECT_EQ(r.exit_code, 3) << "judged against this card's 320 V bus, as apply would be: " << r.out << r.err;
  EXPECT_EQ(sim.writes_seen(), writes) << "validate only reads";
}
