// SPDX-License-Identifier: GPL-2.0-or-later
// The CLI's target syntax (eth/target.hpp).
#include "eth/target.hpp"

#include <gtest/gtest.h>

#include "error/error.hpp"

using namespace i20;
using namespace i20::eth;

TEST(EthTarget, UrlFormWithDefaults) {
  const EthTarget t = parse_target("eth://192.168.1.121/ch0");
  EXPECT_EQ(t.host_port.ip, "192.168.1.121");
  EXPECT_EQ(t.host_port.port, 27181);
  EXPECT_EQ(t.sserial_port, 0u);
  EXPECT_EQ(t.channel, 0u);
  EXPECT_EQ(parse_target("eth://192.168.1.121"), t);
  EXPECT_EQ(t.describe(), "eth 192.168.1.121 ch 0");
  EXPECT_EQ(t.url(), "eth://192.168.1.121/ch0");
}

TEST(EthTarget, UrlFormWithUdpPortSserialPortAndChannel) {
  const EthTarget t = parse_target("eth://10.10.10.10:40000/port1/ch5");
  EXPECT_EQ(t.host_port.port, 40000);
  EXPECT_EQ(t.sserial_port, 1u);
  EXPECT_EQ(t.channel, 5u);
  EXPECT_EQ(t.channel_mask(), 0x20);
  EXPECT_EQ(t.describe(), "eth 10.10.10.10:40000 port 1 ch 5");
  EXPECT_EQ(parse_target(t.url()), t);
}

TEST(EthTarget, FlagForm) {
  EXPECT_EQ(make_target("192.168.1.121", 0), parse_target("eth://192.168.1.121/ch0"));
  EXPECT_EQ(make_target("127.0.0.1:27182", 7, 1), parse_target("eth://127.0.0.1:27182/port1/ch7"));
  EXPECT_THROW(make_target("192.168.1.121", 8), UsageError);
  EXPECT_THROW(make_target("192.168.1.121", 0, 4), UsageError);
}

TEST(EthTarget, RejectsMalformedTargetsWithTheSyntax) {
  EXPECT_FALSE(is_eth_url("/dev/ttyUSB0"));
  EXPECT_TRUE(is_eth_url("eth://1.2.3.4"));
  for (const char* bad : {"/dev/ttyUSB0", "eth://", "eth://192.168.1/ch0", "eth://192.168.1.256/ch0",
                          "eth://card.local/ch0", "eth://192.168.1.121:0/ch0", "eth://192.168.1.121:70000",
                          "eth://192.168.1.121/ch", "eth://192.168.1.121/ch8", "eth://192.168.1.121/chx",
                          "eth://192.168.1.121/ch0/port1", "eth://192.168.1.121/bogus"}) {
    EXPECT_THROW(parse_target(bad), UsageError) << bad;
  }
  try {
    parse_target("eth://192.168.1.121/bogus");
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("eth://IP[:UDPPORT][/portP][/chN]"), std::string::npos);
  }
}

TEST(EthTarget, HostPort) {
  EXPECT_EQ(parse_host_port("127.0.0.1").describe(), "127.0.0.1");
  EXPECT_EQ(parse_host_port("127.0.0.1:40000").describe(), "127.0.0.1:40000");
  EXPECT_THROW(parse_host_port("127.0.0.1:"), UsageError);
  EXPECT_THROW(parse_host_port("localhost"), UsageError);
}
