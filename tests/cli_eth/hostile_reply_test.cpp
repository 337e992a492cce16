// SPDX-License-Identifier: GPL-2.0-or-later
// The bad-input table's network rows: `i20 --eth` behind a proxy that spoils the virtual
// 7I96S's replies from one packet on (an answer from another port, a truncated or oversized
// datagram, a stale reply of an earlier packet). Each case asserts the one-line error, the
// exit code (1: the card was not reached, nothing written) and, by the virtual 8I20's own
// memory, that nothing was written.
#include <gtest/gtest.h>

#include <atomic>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <mutex>
#include <regex>
#include <thread>

#include "fixtures.hpp"
#include "harness.hpp"
#include "sim/ground_truth.hpp"

using namespace i20;
using namespace std::chrono_literals;

namespace {

using udp = boost::asio::ip::udp;

enum class Spoil { WrongSender, Truncated, Oversized, Stale };

// Relays datagrams between the tool and the card; from packet `from` on, every reply is
// spoiled. Stale: the reply to the packet before `from` is sent again in place of the new one.
class SpoilingProxy {
 public:
  SpoilingProxy(eth::HostPort host_port, Spoil spoil, std::size_t from)
      : card_(boost::asio::ip::make_address_v4(host_port.ip), host_port.port), spoil_(spoil), from_(from) {
    for (udp::socket* s : {&front_, &back_, &impostor_}) {
      s->open(udp::v4());
      s->bind(udp::endpoint(boost::asio::ip::make_address_v4("127.0.0.1"), 0));
    }
    front_.non_blocking(true);
    thread_ = std::thread([this] { loop(); });
  }
  ~SpoilingProxy() {
    stop_ = true;
    thread_.join();
  }
  SpoilingProxy(const SpoilingProxy&) = delete;
  SpoilingProxy& operator=(const SpoilingProxy&) = delete;

  std::string address() const { return "127.0.0.1:" + std::to_string(front_.local_endpoint().port()); }
  std::size_t packets() const { return packets_; }

 private:
  void loop() {
    std::vector<std::uint8_t> buffer(4096);
    while (!stop_) {
      boost::system::error_code ec;
      udp::endpoint tool;
      const std::size_t n = front_.receive_from(boost::asio::buffer(buffer), tool, 0, ec);
      if (ec) {
        std::this_thread::sleep_for(200us);
        continue;
      }
      back_.send_to(boost::asio::buffer(buffer.data(), n), card_);
      std::vector<std::uint8_t> reply(4096);
      udp::endpoint from;
      reply.resize(back_.receive_from(boost::asio::buffer(reply), from));
      const std::size_t index = packets_++;
      if (index < from_) {
        last_good_ = reply;
        front_.send_to(boost::asio::buffer(reply), tool);
        continue;
      }
      switch (spoil_) {
        case Spoil::WrongSender: impostor_.send_to(boost::asio::buffer(reply), tool); break;
        case Spoil::Truncated:
          reply.resize(reply.size() - 1);
          front_.send_to(boost::asio::buffer(reply), tool);
          break;
        case Spoil::Oversized:
          reply.resize(reply.size() + 4, 0xA5);
          front_.send_to(boost::asio::buffer(reply), tool);
          break;
        case Spoil::Stale: front_.send_to(boost::asio::buffer(last_good_), tool); break;
      }
    }
  }

  boost::asio::io_context io_;
  udp::socket front_{io_};
  udp::socket back_{io_};
  udp::socket impostor_{io_};
  udp::endpoint card_;
  Spoil spoil_;
  std::size_t from_;
  std::vector<std::uint8_t> last_good_;
  std::atomic<std::size_t> packets_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

struct HostileCase {
  std::string name;
  Spoil spoil;
  std::size_t from;
  std::string error;  // the whole of stderr, {CARD} for the address the tool was given
  friend void PrintTo(const HostileCase& c, std::ostream* os) { *os << c.name; }
};

class HostileReplies : public ::testing::TestWithParam<HostileCase> {
 protected:
  sim::GroundTruth truth() {
    return card_.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return sim::capture(a); });
  }
  sim::RegisterMap map() {
    return card_.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.amplifier().map(); });
  }
  test::RunningBoard card_;
};

TEST_P(HostileReplies, OneLineErrorExitOneAndNothingWritten) {
  const HostileCase& c = GetParam();
  SpoilingProxy proxy(card_.address(), c.spoil, c.from);
  const auto before = truth();
  const auto r = test::run(
      "i20", {"--no-user-params", "--eth", proxy.address(), "--timeout", "30", "set", "NVMAXCURRENT=12A"});
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  std::string expected = c.error;
  if (const auto at = expected.find("{CARD}"); at != std::string::npos)
    expected.replace(at, 6, proxy.address());
  // The wait comes from measured round trips (and backs off), so its figure varies with
  // the host's load: compare the message without it.
  const std::regex wait_figure("within [0-9]+ ms");
  EXPECT_EQ(std::regex_replace(r.err, wait_figure, "within {MS}"), expected + "\n");
  EXPECT_GT(proxy.packets(), c.from) << "the spoiled packet was never sent";
  const auto after = truth();
  EXPECT_EQ(sim::unexplained_changes(map(), before, after, {}), std::vector<std::string>{});
  EXPECT_EQ(after.eeprom, before.eeprom) << "the EEPROM changed";
  EXPECT_EQ(after.nv_access, lbp::local::NvAccess::Ram);
  EXPECT_FALSE(after.rpcmem);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, HostileReplies,
    ::testing::Values(
        HostileCase{
            "AnswerFromAnotherPort", Spoil::WrongSender, 0,
            "i20: error: no reply from {CARD} within {MS} (3 attempts); ignored 3 datagrams from another "
            "address or port"},
        HostileCase{"TruncatedReply", Spoil::Truncated, 0,
                    "i20: error: {CARD} answered with 1073 bytes where 1074 were expected; reply ignored"},
        HostileCase{"OversizedReply", Spoil::Oversized, 0,
                    "i20: error: {CARD} answered with 1078 bytes where 1074 were expected; reply ignored"},
        HostileCase{
            "StaleReplyOfTheFirstPacket", Spoil::Stale, 1,
            "i20: error: no reply from {CARD} within {MS} (3 attempts); ignored 3 stale replies to earlier "
            "packets"},
        // The opening's SSLBP packet: COMMAND read as the first write finds it, then each
        // step's write, WaituS and read-back (batched_opening.cpp).
        HostileCase{"TruncatedReplyDuringTheReads", Spoil::Truncated, 2,
                    "i20: error: {CARD} answered with 111 bytes where 112 were expected; reply ignored"},
        HostileCase{
            "AnswersFromAnotherPortDuringTheReads", Spoil::WrongSender, 2,
            "i20: error: no reply from {CARD} within {MS} (3 attempts); ignored 3 datagrams from another "
            "address or port"}),
    [](const auto& info) { return info.param.name; });

}  // namespace
