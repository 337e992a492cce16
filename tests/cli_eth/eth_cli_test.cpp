// Issue 7 end to end: the toolkit's commands work unchanged through a 7I96S's SSLBP
// passthrough, and one EEPROM image is one amplifier whichever way it is reached.
#include <gtest/gtest.h>

#include "harness.hpp"

using namespace i20::test;

namespace {

using Transport = SimProcess::Transport;

Result run_i20(const std::vector<std::string>& target, std::vector<std::string> args) {
  args.insert(args.begin(), target.begin(), target.end());
  args.insert(args.begin(), "--no-user-params");
  return run("i20", args);
}

std::vector<std::string> eth(const SimProcess& sim) {
  return {"--eth", sim.port()};
}
std::vector<std::string> pty(const SimProcess& sim) {
  return {"--port", sim.port()};
}

}  // namespace

TEST(EthCli, NvWrittenOverEthernetReadsBackThroughTheSerialPort) {
  TempDir dir;
  const auto image = (dir / "amp.eeprom").string();
  {
    // The 8I20 on a 7I44 behind a 7I96S, on the manual's 120 V line.
    SimProcess card({"--eeprom", image, "--busv", "160"}, Transport::Eth);
    const auto r = run_i20(eth(card), {"set", "NVBRAKEONV=190V", "NVBRAKEOFFV=170V", "NVMAXCURRENT=7.5A"});
    ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    EXPECT_NE(r.out.find("APPLIED AND VERIFIED: 3 values written"), std::string::npos) << r.out;
  }
  SimProcess bench({"--eeprom", image});  // the same amplifier moved to a 3I22 (W6 down)
  EXPECT_EQ(run_i20(pty(bench), {"get", "NVBRAKEONV", "NVBRAKEOFFV", "NVMAXCURRENT"}).out,
            "NVBRAKEONV = 190.00 V\nNVBRAKEOFFV = 170.00 V\nNVMAXCURRENT = 7.50 A\n");
}

TEST(EthCli, NvWrittenThroughTheSerialPortReadsBackOverEthernet) {
  TempDir dir;
  const auto image = (dir / "amp.eeprom").string();
  {
    SimProcess bench({"--eeprom", image});
    ASSERT_EQ(run("wpd", {"--port", bench.port(), "--no-user-params", "NVBRAKEOFFV", "17000"}).exit_code, 0);
  }
  SimProcess card({"--eeprom", image}, Transport::Eth);
  const auto r = run("rpd", {"--port", "eth://" + card.port() + "/ch0", "--no-user-params", "NVBRAKEOFFV"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "17000\n");
}

TEST(EthCli, EveryReadCommandWorksUnchanged) {
  SimProcess card({}, Transport::Eth);
  auto r = run_i20(eth(card), {"info"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("8I20 on eth://" + card.port() + "/ch0"), std::string::npos) << r.out;
  r = run_i20(eth(card), {"dump"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("NVKQI"), std::string::npos);
  EXPECT_NE(r.out.find("UNITNUMBER"), std::string::npos);
  r = run_i20({"--eth", card.port(), "--channel", "0"}, {"get", "--raw", "NVKQP", "BUSV"});
  EXPECT_EQ(r.out, "NVKQP = 50\nBUSV = 32000\n") << r.err;
}

TEST(EthCli, SafetyRefusalsSendNothingOverEthernetEither) {
  SimProcess card({}, Transport::Eth);
  const auto r = run_i20(eth(card), {"set", "NVMAXCURRENT=31A"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("outside its valid range"), std::string::npos) << r.err;
  EXPECT_EQ(run_i20(eth(card), {"get", "--raw", "NVMAXCURRENT"}).out, "NVMAXCURRENT = 1000\n");
}

TEST(EthCli, ScanListsTheCardItsPortAndThe8I20) {
  SimProcess card({}, Transport::Eth);
  const auto r = run_i20(eth(card), {"scan"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("7I96S at " + card.port()), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("SSERIAL port 0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("ch 0: 8I20 unit 74565"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("eth://" + card.port() + "/ch0"), std::string::npos) << r.out;
  const auto j = run_i20(eth(card), {"--json", "scan"});
  EXPECT_NE(j.out.find("\"is_8i20\": true"), std::string::npos) << j.out;
}

TEST(EthCli, FaultsReadLatchedFaultsWithoutClearingThemOnAnyFirmware) {
  // A shuffled map: the database's RAM addresses are wrong on this card, yet the card's own
  // RPC table names FAULT and STATUS, and the setup-mode passthrough reads them as they are.
  SimProcess card({"--random-map", "5", "--enable", "off"}, Transport::Eth);
  card.control("enable on");  // the fault stays latched; only CLEARFAULT (or a normal start) clears it
  for (int i = 0; i < 3; ++i) {
    const auto r = run_i20(eth(card), {"faults"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("FAULT 0x0002"), std::string::npos) << "read " << i << ": " << r.out;
    EXPECT_NE(r.out.find("NOENABLEFAULT"), std::string::npos) << r.out;
    EXPECT_EQ(r.err.find("not confirmed"), std::string::npos) << r.err;
  }
  EXPECT_EQ(card.control("get FAULT"), "2") << "reading faults must not clear them";
}

TEST(EthCli, WatchReportsLatchedFaultsBeforeNormalModeClearsThem) {
  SimProcess card({"--random-map", "5", "--enable", "off"}, Transport::Eth);
  card.control("enable on");
  card.control("busv 48");
  const auto r = run_i20(eth(card), {"watch", "--count", "3", "--plain", "--interval", "50"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto latched = r.out.find("FAULT set: NOENABLEFAULT");
  const auto notice = r.out.find("its start CLEARS the latched faults");
  EXPECT_NE(latched, std::string::npos) << r.out;
  EXPECT_NE(notice, std::string::npos) << r.out;
  EXPECT_NE(r.out.find("BUSV 48.00 V"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("3 samples"), std::string::npos) << r.out;
}

TEST(EthCli, FleetAppliesToSerialAndEthernetTargetsTogether) {
  SimProcess bench({"--busv", "160"});  // both on the profile's 120 V line
  SimProcess card({"--busv", "160"}, Transport::Eth);
  const auto profile = (source_dir() / "profiles" / "line-120v.yaml").string();
  const auto r =
      run("i20", {"--no-user-params", "profile", "apply", profile, "--target", bench.port(), "--target",
                  "eth://" + card.port() + "/ch0", "--backup-dir", TempDir().path().string()});
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_EQ(run_i20(eth(card), {"get", "NVBRAKEONV"}).out, "NVBRAKEONV = 190.00 V\n");
  EXPECT_EQ(run_i20(pty(bench), {"get", "NVBRAKEONV"}).out, "NVBRAKEONV = 190.00 V\n");
}
