// SPDX-License-Identifier: GPL-2.0-or-later
// Card identification, HostMot2 discovery and scan over UDP against the virtual card.
#include <gtest/gtest.h>

#include "eth/anything_io.hpp"
#include "eth/errors.hpp"
#include "eth/scan.hpp"
#include "eth/sslbp_port.hpp"
#include "eth/udp_client.hpp"
#include "fixtures.hpp"
#include "programs_timing.hpp"

using namespace i20;
using namespace i20::eth;
namespace hm2 = i20::lbp::hm2;

namespace {

ethsim::ServerOptions card_7i92t() {
  ethsim::ServerOptions o;
  o.card = ethsim::BoardKind::I7i92t;
  o.amplifiers = {{0, 0}, {0, 3}, {1, 7}};
  return o;
}

}  // namespace

TEST(EthDiscovery, IdentifiesThe7i96sFromSpace7) {
  test::RunningBoard card;
  UdpClient bus(card.address().ip, card.address().port, programs_timing::udp());
  const BoardIdentity id = identify(bus);
  EXPECT_EQ(id.card_name, "7I96S");
  EXPECT_EQ(id.lbp16_version, 3);
  EXPECT_TRUE(id.has_timer_space());
  EXPECT_EQ(bus.stats().packets_sent, 1u);
}

TEST(EthDiscovery, ReadsIdromModulesPinsAndLocatesSserial) {
  test::RunningBoard card;
  UdpClient bus(card.address().ip, card.address().port, programs_timing::udp());
  const HostMot2Info info = read_hostmot2(bus);
  EXPECT_EQ(bus.stats().packets_sent, 3u);  // ident area, IDROM, modules + pins
  EXPECT_EQ(info.ident.config_name, "HOSTMOT2");
  EXPECT_EQ(info.idrom.board_name, "MESA7I96");
  EXPECT_EQ(info.pins.size(), 51u);
  ASSERT_NE(info.find(hm2::gtag::kSserial), nullptr);
  const auto ports = info.sserial_ports();
  ASSERT_EQ(ports.size(), 1u);
  EXPECT_EQ(ports[0].registers.command, 0x5B00);
  EXPECT_EQ(ports[0].registers.data, 0x5C00);
  EXPECT_EQ(ports[0].registers.cs(0), 0x5D00);
  EXPECT_EQ(ports[0].registers.interface0(0), 0x5E00);
  EXPECT_EQ(ports[0].registers.interface1(0), 0x5F00);
  EXPECT_THROW(find_sserial_port(info, 1), DiscoveryError);
  const auto sserial_pins = std::count_if(info.pins.begin(), info.pins.end(), [](const auto& p) {
    return p.secondary_tag == hm2::gtag::kSserial;
  });
  EXPECT_EQ(sserial_pins, 3);  // RX, TX, TXEN of the one RS-422 channel
}

TEST(EthDiscovery, NotAHostMot2CardIsNamedAsSuch) {
  test::ScriptedBoard card([](const lbp::Bytes& request, const auto& client, test::ScriptedBoard::Sockets s) {
    s.card.send_to(boost::asio::buffer(test::zero_card_reply(request)), client);
  });
  UdpClient bus("127.0.0.1", card.port(), programs_timing::udp());
  try {
    read_hostmot2(bus);
    FAIL();
  } catch (const DiscoveryError& e) {
    EXPECT_NE(std::string(e.what()).find("expected 0x55AACAFE"), std::string::npos) << e.what();
  }
}

TEST(EthDiscovery, SslbpLocalParameters) {
  test::RunningBoard card;
  UdpClient bus(card.address().ip, card.address().port, programs_timing::udp());
  SslbpPort port(bus, find_sserial_port(read_hostmot2(bus), 0), true, programs_timing::sslbp());
  port.stop_all();
  const SslbpParameters p = port.read_parameters();
  EXPECT_EQ(p.channels, 1);
  EXPECT_EQ(p.width, 1);
  EXPECT_EQ(p.clock_hz, 100'000'000u);
  EXPECT_EQ(p.version(), "0.40");
  EXPECT_EQ(port.read_baud_rate(p, 0), 2'500'000u);
  // A local read is COMMAND 0x2000|addr then DATA: one round trip when it completes
  // inside the packet.
  const auto before = bus.stats().packets_sent;
  port.read_local(lbp::hm2::sslbp::param::kChannels);
  EXPECT_EQ(bus.stats().packets_sent - before, 1u);
}

TEST(EthDiscovery, ScanFindsThe8i20OnThe7i96s) {
  test::RunningBoard card;
  const ScanResult r = scan(card.address(), programs_timing::scan());
  EXPECT_EQ(r.card.card_name, "7I96S");
  EXPECT_EQ(r.board_name, "MESA7I96");
  EXPECT_EQ(r.config_name, "HOSTMOT2");
  ASSERT_EQ(r.ports.size(), 1u);
  ASSERT_EQ(r.ports[0].channels.size(), 1u);
  const ChannelReport& ch = r.ports[0].channels[0];
  EXPECT_TRUE(ch.is_8i20());
  EXPECT_EQ(ch.unit_number, 0x00012345u);
  EXPECT_EQ(ch.status, "ok");
  ASSERT_EQ(r.targets().size(), 1u);
  EXPECT_EQ(r.targets()[0].url(), card.target(0).url());
  // Scanning leaves the port stopped.
  card.server().with_card(
      [](ethsim::VirtualBoard& c) { EXPECT_EQ(c.sslbp(0).mode(0), ethsim::ChannelMode::Stopped); });
}

TEST(EthDiscovery, ScanOfA7i92tWithTwoPortsOfEightChannels) {
  test::RunningBoard card(card_7i92t());
  const ScanResult r = scan(card.address(), programs_timing::scan());
  EXPECT_EQ(r.card.card_name, "7I92T");
  ASSERT_EQ(r.ports.size(), 2u);
  for (const auto& port : r.ports) ASSERT_EQ(port.channels.size(), 8u);
  EXPECT_EQ(r.ports[1].command_address, 0x5B40);
  std::vector<std::string> found;
  for (const auto& t : r.targets()) found.push_back(t.describe());
  const std::string a = "eth " + card.address().describe();
  EXPECT_EQ(found, (std::vector<std::string>{a + " ch 0", a + " ch 3", a + " port 1 ch 7"}));
  EXPECT_EQ(r.ports[0].channels[3].unit_number, 0x00012346u);
  EXPECT_EQ(r.ports[1].channels[7].unit_number, 0x00012347u);
  const ChannelReport& empty = r.ports[0].channels[1];
  EXPECT_FALSE(empty.answered);
  EXPECT_NE(empty.status.find("timeout"), std::string::npos) << empty.status;
}
