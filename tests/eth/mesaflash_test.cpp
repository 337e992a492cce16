// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual card against Debian's real mesaflash (an independent LBP16 client).
// mesaflash always talks to UDP port 27181, so the server binds 27181 on a loopback
// address of its own (127.x.y.z, all of 127/8 is loopback on Linux) to stay clear of
// anything else listening on 127.0.0.1:27181.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "ethsim/server.hpp"
#include "fixtures.hpp"

using namespace i20;

namespace {

constexpr const char* kMesaflash = "/usr/bin/mesaflash";

std::string run(const std::string& command) {
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen((command + " 2>&1").c_str(), "r"), pclose);
  if (!pipe) return out;
  std::array<char, 512> buffer{};
  while (fgets(buffer.data(), static_cast<int>(buffer.size()), pipe.get())) out += buffer.data();
  return out;
}

// A loopback address unlikely to be in use by a parallel test run.
std::string private_loopback() {
  const unsigned pid = static_cast<unsigned>(getpid());
  return "127.27." + std::to_string(1 + pid % 250) + "." + std::to_string(1 + (pid / 250) % 250);
}

class EthMesaflash : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(kMesaflash)) GTEST_SKIP() << "mesaflash is not installed";
  }
  // Overloaded rather than defaulted: a default-argument ServerOptions temporary makes
  // GCC 12 at -O3 report -Wmaybe-uninitialized (a false positive) at every call site.
  std::unique_ptr<ethsim::BoardServer> serve() { return serve(ethsim::ServerOptions()); }
  std::unique_ptr<ethsim::BoardServer> serve(ethsim::ServerOptions options) {
    options.listen = eth::HostPort{.ip = private_loopback(), .port = 27181};
    auto server = std::make_unique<ethsim::BoardServer>(options);
    server->start();
    return server;
  }
  // mesaflash waits only 2 ms for the answer to its first packet; on a loaded machine the
  // server thread may miss that, and mesaflash then says "No ... board found": try again
  // (a miss costs milliseconds, so many tries cost little and outlast a busy moment).
  std::string mesaflash(const std::string& device, const std::string& args) {
    std::string out;
    for (int attempt = 0; attempt < 50; ++attempt) {
      out = run("timeout 30 " + std::string(kMesaflash) + " --device " + device + " --addr " +
                private_loopback() + " " + args);
      if (out.find("board found") == std::string::npos) break;
    }
    return out;
  }
};

}  // namespace

TEST_F(EthMesaflash, FindsThe7i96s) {
  const auto server = serve();
  const std::string out = mesaflash("7i96s", "");
  EXPECT_NE(out.find("ETH device 7I96S at ip=" + private_loopback()), std::string::npos) << out;
}

TEST_F(EthMesaflash, ReadhmidPrintsTheConfiguration) {
  const auto server = serve();
  const std::string out = mesaflash("7i96s", "--readhmid");
  EXPECT_NE(out.find("Configuration Name: HOSTMOT2"), std::string::npos) << out;
  EXPECT_NE(out.find("BoardName : MESA7I96"), std::string::npos) << out;
  EXPECT_NE(out.find("Module: SSerial"), std::string::npos) << out;
  EXPECT_NE(out.find("BaseAddress: 5B00"), std::string::npos) << out;
  EXPECT_NE(out.find("Module: StepGen"), std::string::npos) << out;
  EXPECT_NE(out.find("RXData0"), std::string::npos) << out;
  EXPECT_NE(out.find("TXData0"), std::string::npos) << out;
  // The feedback hostmot2 needs for bldc: the encoder on TB2 and the isolated inputs as InM.
  EXPECT_NE(out.find("Module: QCount"), std::string::npos) << out;
  EXPECT_NE(out.find("Module: InM"), std::string::npos) << out;
  EXPECT_NE(out.find("BaseAddress: 8500"), std::string::npos) << out;
  EXPECT_NE(out.find("Quad-IDX"), std::string::npos) << out;
  EXPECT_NE(out.find("Input10"), std::string::npos) << out;
}

TEST_F(EthMesaflash, SserialListsThe8i20OnItsChannel) {
  const auto server = serve();
  const std::string out = mesaflash("7i96s", "--sserial");
  EXPECT_NE(out.find("SSLBP port 0:"), std::string::npos) << out;
  EXPECT_NE(out.find("SSLBP Channels: 1"), std::string::npos) << out;
  EXPECT_NE(out.find("sserial device at channel 0: 8I20 (unit 0x00012345)"), std::string::npos) << out;
}

TEST_F(EthMesaflash, VerboseInfoShowsTheSpacesAndEeprom) {
  const auto server = serve();
  const std::string out = mesaflash("7i96s", "--verbose");
  EXPECT_NE(out.find("protocol: LBP16 version 3"), std::string::npos) << out;
  EXPECT_NE(out.find("0: HostMot2 (registers, RW, 32-bit) [size=64K]"), std::string::npos) << out;
  EXPECT_NE(out.find("ip address: 192.168.1.121"), std::string::npos) << out;
  EXPECT_NE(out.find("board name: 7I96S"), std::string::npos) << out;
}

TEST_F(EthMesaflash, RegisterReadAndWrite) {
  const auto server = serve();
  EXPECT_NE(mesaflash("7i96s", "--rpo 0x100").find("55AACAFE"), std::string::npos);
  mesaflash("7i96s", "--wpo 0x7000=0x12345678");
  // mesaflash sends the write and exits without waiting for an answer: the server's
  // thread handles the datagram when it next runs, which may be after mesaflash has gone.
  const auto reg = [&] {
    return server->with_card([](ethsim::VirtualBoard& c) { return c.hm2_register(0x7000); });
  };
  EXPECT_TRUE(test::eventually([&] { return reg() == 0x12345678u; })) << std::hex << reg();
}

TEST_F(EthMesaflash, The7i92tWithEightChannelsPerPort) {
  ethsim::ServerOptions options;
  options.card = ethsim::BoardKind::I7i92t;
  options.amplifiers = {{0, 0}, {0, 3}};
  const auto server = serve(options);
  const std::string hmid = mesaflash("7i92t", "--readhmid");
  EXPECT_NE(hmid.find("BoardName : MESA7I92"), std::string::npos) << hmid;
  EXPECT_NE(hmid.find("There are 2 of SSerial in configuration"), std::string::npos) << hmid;
  const std::string out = mesaflash("7i92t", "--sserial");
  EXPECT_NE(out.find("SSLBP Channels: 8"), std::string::npos) << out;
  EXPECT_NE(out.find("sserial device at channel 0: 8I20 (unit 0x00012345)"), std::string::npos) << out;
  EXPECT_NE(out.find("sserial device at channel 3: 8I20 (unit 0x00012346)"), std::string::npos) << out;
}
