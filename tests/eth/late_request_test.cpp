// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 18 item 1 at the link: the LBP commands of an EEPROM change (NV access on, the cell,
// NV access off, the mode read back) through a network that holds 10% of the datagrams back
// 80-400 ms, past the 50 ms reply timeout, and repeats a few. Without the fence
// (fenced_transport.hpp) a late "NV access on" can land after the "off" while the link
// reports every command done; with it, a link that reports done leaves the card as told.
// (At this level the unfenced link showed no false done in 40 changes either: the
// reproduction is the CLI test, tests/cli_eth/late_datagram_test.cpp.)
// Judged by the virtual 8I20's memory once the network delivered everything it held.
#include <gtest/gtest.h>

#include <iostream>

#include "eth/fenced_transport.hpp"
#include "eth/passthrough_link.hpp"
#include "ethsim/faulty_network.hpp"
#include "fixtures.hpp"
#include "lbp/command.hpp"
#include "sim/ground_truth.hpp"

using namespace i20;
using namespace std::chrono_literals;

namespace {

struct Tally {
  unsigned done = 0, failed = 0, false_done = 0, left_in_nv = 0;
};

ethsim::ServerOptions two_channel_7i92t() {
  ethsim::ServerOptions o;
  o.card = ethsim::CardKind::I7i92t;
  o.amplifiers = {{0, 0}, {0, 1}};
  return o;
}

// One change of NVKQP on channel 1; `fenced` puts the ledger between the link and UDP.
void change_once(std::uint64_t seed, bool fenced, const ethsim::NetworkFaults& shape, Tally& tally) {
  test::RunningCard card(two_channel_7i92t());
  ethsim::NetworkFaults faults = shape;
  faults.seed = seed;
  ethsim::FaultyNetwork network(card.address(), faults);
  const sim::Register cell = card.with_amplifier(0, 1, [](sim::Virtual8i20& a) {
    return *a.amplifier().map().find("NVKQP");
  });
  const std::uint16_t wanted = 119;
  const eth::HostPort proxy = eth::parse_host_port(network.address());
  bool done = false;
  try {
    std::unique_ptr<eth::Lbp16Transport> bus = std::make_unique<eth::UdpClient>(proxy.ip, proxy.port);
    if (fenced) bus = std::make_unique<eth::FencedTransport>(std::move(bus));
    eth::SslbpPassthroughLink link(std::move(bus), eth::EthTarget{.card = proxy, .channel = 1});
    const std::vector<lbp::Command> on{lbp::set_nv_access(lbp::local::NvAccess::Eeprom)};
    const std::vector<lbp::Command> write{
        lbp::write(cell.address, lbp::DataSize::Two, wanted)};
    const std::vector<lbp::Command> off{lbp::set_nv_access(lbp::local::NvAccess::Ram)};
    const std::vector<lbp::Command> mode{lbp::local_read(lbp::local::kGetNvAccess)};
    link.execute(on);
    link.execute(write);
    link.execute(off);
    done = link.execute(mode).front().at(0) == 0;  // what a tool would report on
  } catch (const Error&) {
    // An honest failure: the tool would say the change may be incomplete.
  }
  ASSERT_TRUE(network.wait_idle(5s));
  const sim::GroundTruth truth = card.with_amplifier(0, 1, [](sim::Virtual8i20& a) { return sim::capture(a); });
  const auto nv = truth.nv_access;
  const auto value = sim::value_in(truth, cell);
  const bool in_nv = nv != lbp::local::NvAccess::Ram;
  tally.left_in_nv += in_nv;
  if (!done) {
    ++tally.failed;
    return;
  }
  ++tally.done;
  if (in_nv || value != wanted) {
    ++tally.false_done;
    std::cerr << (fenced ? "fenced" : "unfenced") << " seed " << seed << ": reported done, card in NV mode "
              << int(nv) << ", NVKQP " << value << "\n";
  }
}

Tally trials(bool fenced, const ethsim::NetworkFaults& shape, unsigned count) {
  Tally t;
  for (unsigned seed = 1; seed <= count; ++seed) change_once(seed, fenced, shape, t);
  std::cout << (fenced ? "fenced:   " : "unfenced: ") << count << " changes, " << t.done << " done, "
            << t.failed << " failed, " << t.false_done << " false done, " << t.left_in_nv
            << " left in NV access mode\n";
  return t;
}

// Delays only: a repeated datagram that lands after the last packet is beyond any client.
const ethsim::NetworkFaults kLateAndRepeated{.delay_share = 0.10};

TEST(LateRequests, WithTheFenceNoFalseDone) {
  const Tally t = trials(true, kLateAndRepeated, 40);
  EXPECT_EQ(t.false_done, 0u);
  EXPECT_GT(t.done, 0u);
}

}  // namespace
