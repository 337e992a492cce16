// SPDX-License-Identifier: GPL-2.0-or-later
// A network that delivers our requests twice (a switch or a Wi-Fi bridge repeating frames):
// the card counts each copy as a packet received and answered, just as it counts another
// host's. The UDP client tells the copies by their sequence tag (a second reply to a packet
// already answered) and counts them as ours, so the running-host watch does not take our own
// repeated datagrams for LinuxCNC starting (the Ethernet soak's seed 2026 found sessions that
// then refused their own rollback and left the brake thresholds crossed).
#include <gtest/gtest.h>

#include <chrono>
#include <span>

#include "eth/running_host.hpp"
#include "eth/udp_client.hpp"
#include "ethsim/faulty_network.hpp"
#include "fixtures.hpp"
#include "programs_timing.hpp"

using namespace i20;
using namespace i20::eth;
using namespace std::chrono_literals;

namespace {

const SserialPort kPort{.index = 0, .registers = {.command = 0x5B00, .data = 0x5C00}};

// The running-host watch over a network that delivers every request twice, the copy within
// 2 ms, to `card`; the client it used, for its counts.
struct RepeatingNetworkWatch {
  explicit RepeatingNetworkWatch(test::RunningBoard& card)
      : network(card.address(), faults()),
        bus(parse_host_port(network.address()).ip, parse_host_port(network.address()).port,
            programs_timing::udp()),
        seen(observe_host_activity(bus, std::span(&kPort, 1), check)) {}
  static ethsim::NetworkFaults faults() {
    ethsim::NetworkFaults f;
    f.duplicate_share = 1.0;
    f.max_delay = 2ms;
    f.replies = false;
    return f;
  }
  ethsim::FaultyNetwork network;
  UdpClient bus;
  RunningHostCheck check = programs_timing::running_host();
  HostActivity seen;
};

}  // namespace

TEST(EthNetworkRepeats, OurRepeatedRequestsAreCountedAsOursAndShowNoHost) {
  test::RunningBoard card;
  const RepeatingNetworkWatch watch(card);
  const TransportStats stats = watch.bus.stats();
  EXPECT_GT(stats.network_repeats, 0u) << "the copies' replies were not told apart";
  EXPECT_EQ(stats.ours(), stats.packets_sent + stats.network_repeats);
  EXPECT_FALSE(host_is_running(watch.seen, watch.check)) << watch.seen.describe();
  EXPECT_LE(watch.seen.foreign_packets(), watch.check.foreign_packet_limit) << watch.seen.describe();
}

// The same watch beside a host that really runs still sees it: the copies of ours are
// discounted, another host's packets are not.
TEST(EthNetworkRepeats, AHostThatRunsIsStillSeenThroughARepeatingNetwork) {
  test::RunningBoard card;
  card.server().start_host(ethsim::HostOptions{});
  const RepeatingNetworkWatch watch(card);
  EXPECT_TRUE(host_is_running(watch.seen, watch.check)) << watch.seen.describe();
}
