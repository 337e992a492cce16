// SPDX-License-Identifier: GPL-2.0-or-later
// Issue 19, "one retry budget": ops owns it (ops/core/retry.hpp) and hands it down where the
// links are built (ops::timing::serial_link, ops::timing::passthrough), so the layers
// never multiply their resends. The worst case asserted here: a read whose replies are all
// lost reaches the card at most RetryPolicy::attempts (3) times in all, over serial and over
// Ethernet, and ends with an error that says so; a write whose replies are lost is sent
// once and never again without a read-back showing it missing. Every count is taken where
// the requests land: the simulated 8I20's own command counter, or the packets on the way.
// The budget is asserted alone (no silence window); the window's own tests follow it: a card
// that answers again within it is read, and the change finishes, instead of ending uncertain.
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <functional>
#include <iostream>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "device/errors.hpp"
#include "eth/fenced_transport.hpp"
#include "eth/passthrough_port.hpp"
#include "eth/udp_client.hpp"
#include "ethsim/faulty_network.hpp"
#include "fixtures.hpp"
#include "lbp/header.hpp"
#include "ops/core/amp.hpp"
#include "ops/core/amp_cell_access.hpp"
#include "ops/core/cancel.hpp"
#include "ops/core/read.hpp"
#include "ops/core/timing.hpp"
#include "sim/param_map.hpp"
#include "sim/sim_stream.hpp"

using namespace i20;
using namespace std::chrono_literals;

namespace {

// The budget alone: a silent card is not waited for.
ops::RetryPolicy budget_only() {
  ops::RetryPolicy retry;
  retry.silence_window = 0ms;
  return retry;
}

// One batch of three reads: over Ethernet three DOITs in one packet.
const std::vector<std::string> kRead{"BUSV", "FAULT", "STATUS"};

// Reads kRead as every i20 command does (Amp::with_retries); the error's text when it fails.
std::string read_or_error(ops::Amp& amp) {
  try {
    ops::read_values(amp, kRead, ops::Unconfirmed::Read);
  } catch (const link::LinkError& e) {
    return e.what();
  }
  return {};
}

// ---------------------------------------------------------------- serial

// Counts what ops hands the link: batches with a write (data or local), and the others.
class CountingLink final : public link::Link {
 public:
  explicit CountingLink(std::unique_ptr<link::Link> inner) : inner_(std::move(inner)) {}
  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override {
    const bool writes = std::any_of(batch.begin(), batch.end(), [](const lbp::Command& c) {
      const auto kind = lbp::kind_of(c.bytes.front());
      return kind == lbp::CommandKind::LocalWrite ||
             (kind == lbp::CommandKind::Data && lbp::DataHeader::decode(c.bytes.front()).write);
    });
    ++(writes ? writing_batches : reading_batches);
    commands += batch.size();
    return inner_->execute(batch);
  }
  std::string describe() const override { return inner_->describe(); }
  unsigned writing_batches = 0;
  unsigned reading_batches = 0;
  std::uint64_t commands = 0;

 private:
  std::unique_ptr<link::Link> inner_;
};

// The serial simulator behind the link ops builds for a serial port, opened as an ops::Amp.
struct SerialRig {
  sim::SimStream* stream = nullptr;
  CountingLink* counting = nullptr;
  std::unique_ptr<ops::Amp> amp;

  explicit SerialRig(const ops::RetryPolicy& retry = budget_only()) {
    ops::LinkSettings settings;
    settings.timeout_ms = 20;
    sim::SimOptions sim;
    sim.device.map = sim::register_map_from(params::ParamDb::builtin());
    auto s = std::make_unique<sim::SimStream>(std::move(sim));
    stream = s.get();
    auto link = std::make_unique<CountingLink>(
        std::make_unique<link::PipelinedLink>(std::move(s), ops::timing::serial_link(settings, retry)));
    counting = link.get();
    amp = ops::Amp::attach(std::move(link), ops::parse_endpoint("sim"), params::ParamDb::builtin(), retry);
  }
  std::uint64_t executed() {
    return stream->with_card([](sim::Virtual8i20& c) { return c.stats().commands_executed; });
  }
};

TEST(RetryBudget, SerialReadWithEveryReplyLostIsSentAtMostThreeTimes) {
  SerialRig rig;
  auto before = rig.executed();
  ASSERT_EQ(read_or_error(*rig.amp), "");
  const auto per_read = rig.executed() - before;
  ASSERT_GT(per_read, 0u);

  rig.stream->control("drop 1");
  before = rig.executed();
  const std::string error = read_or_error(*rig.amp);
  const auto sends = (rig.executed() - before) / per_read;
  EXPECT_EQ(sends, rig.amp->retry().attempts) << "the read reached the card " << sends << " times";
  EXPECT_LE(sends, 3u);
  EXPECT_NE(error, "") << "a read with every reply lost must fail";
  EXPECT_NE(error.find("no reply"), std::string::npos) << error;
}

TEST(RetryBudget, SerialWriteWithEveryReplyLostIsSentOnceAndReadBackAtMostThreeTimes) {
  SerialRig rig;
  ops::AmpCellAccess access(*rig.amp, device::WriteOptions{});
  const std::int64_t kqp = ops::read_values(*rig.amp, std::vector<std::string>{"KQP"}).front().raw.value();
  access.check_write("KQP", kqp + 1);
  rig.stream->control("drop 1");
  const auto writes_before = rig.counting->writing_batches;
  const auto reads_before = rig.counting->reading_batches;
  const auto commands_before = rig.counting->commands;
  const auto before = rig.executed();
  std::string error;
  try {
    access.write("KQP", kqp + 1);
  } catch (const link::LinkError& e) {
    error = e.what();
  }
  EXPECT_NE(error, "") << "a write with every reply lost must fail";
  const auto writes = rig.counting->writing_batches - writes_before;
  const auto read_backs = rig.counting->reading_batches - reads_before;
  EXPECT_EQ(writes, 1u) << "a write whose fate is unknown must not be sent again blindly";
  EXPECT_LE(read_backs, 3u) << "read back " << read_backs << " times";
  // The link sends each batch once: what reached the card is what ops handed it.
  EXPECT_EQ(rig.executed() - before, rig.counting->commands - commands_before);
}

// ---------------------------------------------------------------- Ethernet

// Between the ledger (FencedTransport) and UDP, as the loss of a datagram sits: counts the
// packets that carry DOITs (the only ones with writes) and, once told, loses their replies
// (the card executed them) or the requests themselves (the card never saw them).
// Read-only packets (the fence's and the port's probes) pass.
class LosingDoits final : public eth::Lbp16Transport {
 public:
  enum class Lose { Nothing, Replies, Requests };
  explicit LosingDoits(std::unique_ptr<eth::Lbp16Transport> inner) : inner_(std::move(inner)) {}
  std::vector<lbp::Bytes> transact(std::span<const lbp::lbp16::Command> commands,
                                   eth::Resend resend) override {
    const bool doits = std::any_of(commands.begin(), commands.end(),
                                   [](const lbp::lbp16::Command& c) { return c.word.write; });
    if (!doits || lose == Lose::Nothing) return inner_->transact(commands, resend);
    ++doit_packets;
    if (lose == Lose::Requests) throw link::TimeoutError("request lost (test)");
    inner_->transact(commands, resend);
    throw link::TimeoutError("reply lost (test)");
  }
  std::string describe() const override { return inner_->describe(); }
  eth::TransportStats stats() const override { return inner_->stats(); }

  Lose lose = Lose::Nothing;
  unsigned doit_packets = 0;  // counted while losing

 private:
  std::unique_ptr<eth::Lbp16Transport> inner_;
};

// The options ops hands an Ethernet link, with waits shortened for a test.
eth::PassthroughOptions eth_options(const ops::RetryPolicy& retry) {
  ops::LinkSettings settings;
  settings.timeout_ms = 20;
  auto options = ops::timing::passthrough(settings, retry);
  options.udp.max_timeout = 100ms;
  options.fence.bound = 100ms;
  return options;
}

std::uint64_t executed(test::RunningBoard& card) {
  return card.with_amplifier(0, 0, [](sim::Virtual8i20& a) { return a.stats().commands_executed; });
}

std::unique_ptr<ops::Amp> open_eth(const eth::HostPort& at, const eth::PassthroughOptions& options,
                                   const ops::RetryPolicy& retry, std::unique_ptr<eth::Lbp16Transport> bus) {
  auto port = std::make_shared<eth::PassthroughPort>(std::shared_ptr<eth::Lbp16Transport>(std::move(bus)), 0,
                                                     std::uint8_t{1}, options);
  const eth::EthTarget target{.host_port = at, .sserial_port = 0, .channel = 0};
  return ops::Amp::attach(port->link(0), ops::parse_endpoint(target.url()), params::ParamDb::builtin(),
                          retry);
}

void PrintTo(LosingDoits::Lose lose, std::ostream* os) {
  *os << (lose == LosingDoits::Lose::Replies ? "Replies" : "Requests");
}

class EthLoss : public ::testing::TestWithParam<LosingDoits::Lose> {};

TEST_P(EthLoss, AReadWhoseDoitPacketsAreAllLostIsSentAtMostThreeTimes) {
  test::RunningBoard card;
  const ops::RetryPolicy retry = budget_only();
  const auto options = eth_options(retry);
  auto losing = std::make_unique<LosingDoits>(
      std::make_unique<eth::UdpClient>(card.address().ip, card.address().port, options.udp));
  LosingDoits* loss = losing.get();
  auto opened = open_eth(card.address(), options, retry,
                         std::make_unique<eth::FencedTransport>(std::move(losing), options.fence));

  auto before = executed(card);
  ASSERT_EQ(read_or_error(*opened), "");
  const auto per_read = executed(card) - before;
  ASSERT_GT(per_read, 0u);

  loss->lose = GetParam();
  before = executed(card);
  const std::string error = read_or_error(*opened);
  EXPECT_NE(error, "") << "a read whose every DOIT packet is lost must fail";
  EXPECT_LE(loss->doit_packets, 3u) << "the read was sent " << loss->doit_packets << " times";
  EXPECT_EQ(loss->doit_packets, retry.attempts);
  const auto arrived = (executed(card) - before) / per_read;
  EXPECT_LE(arrived, 3u) << "the read reached the 8I20 " << arrived << " times";
  EXPECT_NE(error.find("lost"), std::string::npos) << error;
}

INSTANTIATE_TEST_SUITE_P(RetryBudget, EthLoss,
                         ::testing::Values(LosingDoits::Lose::Replies, LosingDoits::Lose::Requests),
                         [](const auto& info) {
                           return info.param == LosingDoits::Lose::Replies ? std::string("Replies")
                                                                           : std::string("Requests");
                         });

// Every reply on the network lost (the faulty network's proxy drops them all), probes
// included: the read reaches the 8I20 at most three times and the error says why.
TEST(RetryBudget, EthReadWithEveryReplyOnTheNetworkLostIsSentAtMostThreeTimes) {
  test::RunningBoard card;
  ethsim::FaultyNetwork network(card.address(), ethsim::NetworkFaults{});
  const eth::HostPort proxy = eth::parse_host_port(network.address());
  const ops::RetryPolicy retry = budget_only();
  const auto options = eth_options(retry);
  auto losing =
      std::make_unique<LosingDoits>(std::make_unique<eth::UdpClient>(proxy.ip, proxy.port, options.udp));
  LosingDoits* counter = losing.get();
  auto opened = open_eth(proxy, options, retry,
                         std::make_unique<eth::FencedTransport>(std::move(losing), options.fence));

  auto before = executed(card);
  ASSERT_EQ(read_or_error(*opened), "");
  const auto per_read = executed(card) - before;
  ASSERT_GT(per_read, 0u);

  network.set_faults(ethsim::NetworkFaults{.drop_share = 1.0, .requests = false, .replies = true});
  before = executed(card);
  const auto sent_before = counter->stats().packets_sent;
  const std::string error = read_or_error(*opened);
  EXPECT_NE(error, "") << "a read with every reply lost must fail";
  ASSERT_TRUE(network.wait_idle(5s));
  const auto arrived = (executed(card) - before) / per_read;
  EXPECT_LE(arrived, 3u) << "the read reached the 8I20 " << arrived << " times";
  EXPECT_GE(arrived, 1u);
  EXPECT_NE(error.find("no reply"), std::string::npos) << error;
  RecordProperty("udp_packets", std::to_string(counter->stats().packets_sent - sent_before));
}

// ---------------------------------------------------------------- the silence window

using Clock = std::chrono::steady_clock;

// Ends the card's silence after `after` from another thread, as a cable put back would.
class Heal {
 public:
  Heal(std::chrono::milliseconds after, std::function<void()> heal)
      : thread_([after, heal = std::move(heal)] {
          std::this_thread::sleep_for(after);
          heal();
        }) {}
  ~Heal() { thread_.join(); }

 private:
  std::thread thread_;
};

// A card silent for 300 ms (every reply dropped): the read is asked again within the window
// and answers; without the window it fails after its three sends.
TEST(SilenceWindow, ASerialCardThatAnswersAgainWithinTheWindowIsRead) {
  SerialRig rig{ops::RetryPolicy{}};
  rig.stream->control("drop 1");
  const auto start = Clock::now();
  std::string error;
  {
    Heal heal(300ms, [&rig] { rig.stream->control("drop 0"); });
    error = read_or_error(*rig.amp);
  }
  EXPECT_EQ(error, "") << "the card answered again 300 ms later, within the 2 s window";
  EXPECT_GE(Clock::now() - start, 300ms);
  EXPECT_GT(rig.amp->probes(), 0u);
  EXPECT_EQ(rig.amp->silences_ended(), 1u);
}

// A card that stays silent is given the window once per silence: the first read fails after
// about the window, the next one at once (after its budget), until the card answers again.
TEST(SilenceWindow, ACardThatStaysSilentGetsTheWindowOncePerSilence) {
  ops::RetryPolicy retry;
  retry.silence_window = 400ms;
  SerialRig rig{retry};
  rig.stream->control("drop 1");
  auto start = Clock::now();
  EXPECT_NE(read_or_error(*rig.amp), "");
  const auto first = Clock::now() - start;
  EXPECT_GE(first, 400ms);
  EXPECT_LT(first, 400ms + 1500ms);
  start = Clock::now();
  EXPECT_NE(read_or_error(*rig.amp), "");
  EXPECT_LT(Clock::now() - start, 350ms) << "the window is per silence, not per exchange";
  rig.stream->control("drop 0");
  EXPECT_EQ(read_or_error(*rig.amp), "");
  // A new silence gets a new window.
  rig.stream->control("drop 1");
  start = Clock::now();
  EXPECT_NE(read_or_error(*rig.amp), "");
  EXPECT_GE(Clock::now() - start, 400ms);
}

// Ctrl-C while the tool waits for a silent card ends the wait (a read changes nothing).
TEST(SilenceWindow, AStopRequestEndsTheWait) {
  ops::StopRequest stop;
  ops::RetryPolicy retry;
  retry.silence_window = 5000ms;
  SerialRig rig{retry};
  rig.amp = nullptr;  // reopened with the stop request below
  {
    sim::SimOptions sim;
    sim.device.map = sim::register_map_from(params::ParamDb::builtin());
    auto s = std::make_unique<sim::SimStream>(std::move(sim));
    rig.stream = s.get();
    ops::LinkSettings settings;
    settings.timeout_ms = 20;
    rig.amp = ops::Amp::attach(
        std::make_unique<link::PipelinedLink>(std::move(s), ops::timing::serial_link(settings, retry)),
        ops::parse_endpoint("sim"), params::ParamDb::builtin(), retry, ops::Cancel(stop, {}));
  }
  rig.stream->control("drop 1");
  const auto start = Clock::now();
  Heal signal(200ms, [&stop] { stop.request(SIGINT); });
  EXPECT_THROW(ops::read_values(*rig.amp, kRead, ops::Unconfirmed::Read), device::Cancelled);
  EXPECT_LT(Clock::now() - start, 2000ms);
}

// A write whose reply is lost while the card goes silent for 300 ms: the read-back waits for
// the card, finds the value (or writes it again), and the write is verified, not uncertain.
TEST(SilenceWindow, AWriteDuringAShortSilenceEndsVerified) {
  SerialRig rig{ops::RetryPolicy{}};
  ops::AmpCellAccess access(*rig.amp, device::WriteOptions{});
  const std::int64_t kqp = ops::read_values(*rig.amp, std::vector<std::string>{"KQP"}).front().raw.value();
  access.check_write("KQP", kqp + 1);
  rig.stream->control("drop 1");
  {
    Heal heal(300ms, [&rig] { rig.stream->control("drop 0"); });
    EXPECT_NO_THROW(access.write("KQP", kqp + 1));
  }
  EXPECT_EQ(ops::read_values(*rig.amp, std::vector<std::string>{"KQP"}).front().raw, kqp + 1);
}

// The Ethernet card resets mid-session (its SSERIAL ports come back stopped): the next
// exchange finds the channel not ready, the port is set up again (the running-host watch
// first), and the read answers instead of failing.
TEST(SilenceWindow, AnEthernetCardThatResetsIsSetUpAgainAndRead) {
  test::RunningBoard card;
  const ops::RetryPolicy retry;
  const auto options = eth_options(retry);
  auto port = eth::PassthroughPort::open(card.address(), 0, std::uint8_t{1}, options);
  auto opened = ops::Amp::attach(port->link(0), ops::parse_endpoint(card.target().url()),
                                 params::ParamDb::builtin(), retry);
  ASSERT_EQ(read_or_error(*opened), "");
  card.server().go_dark(5ms, /*power_loss=*/false);
  ASSERT_TRUE(card.server().wait_until_back(5s));
  EXPECT_EQ(read_or_error(*opened), "");
  EXPECT_GE(port->stats().restarts, 1u);
}

}  // namespace

// ---------------------------------------------------------------- the operation's deadline

// Issue 33 item 6 and issue 40: the operation's deadline (RetryPolicy::operation_deadline,
// counted from the start of the card's opening) is one: past it nothing more is sent (the
// way back excepted, below), and no wait, a silence window or one reply's, runs past it.
// Before it, the same lost read gets its budget and the window (the figures README.md
// "How long a command may take" states, printed here as measured).
TEST(OperationDeadline, ALostReadGetsTheWindowWithinItAndNothingIsSentPastIt) {
  ops::RetryPolicy within;  // the 2 s silence window on, a 20 s deadline
  SerialRig before_deadline{within};
  ASSERT_EQ(read_or_error(*before_deadline.amp), "");
  auto executed = before_deadline.executed();
  ASSERT_EQ(read_or_error(*before_deadline.amp), "");
  const auto per_read = before_deadline.executed() - executed;

  before_deadline.stream->control("drop 1");
  executed = before_deadline.executed();
  auto start = Clock::now();
  EXPECT_NE(read_or_error(*before_deadline.amp), "");
  const auto waited = Clock::now() - start;
  const auto sends = (before_deadline.executed() - executed) / per_read;
  EXPECT_GE(waited, within.silence_window) << "within the deadline a silent card gets the window";
  EXPECT_GE(sends, within.attempts);
  std::cout << "serial, a lost read within the deadline: " << sends << " sends (budget " << within.attempts
            << ", then probes every " << within.probe_interval.count() << " ms), "
            << std::chrono::duration_cast<std::chrono::milliseconds>(waited).count() << " ms\n";

  // Past it: the card answers, but nothing is sent any more.
  ops::RetryPolicy short_deadline = within;
  short_deadline.operation_deadline = 300ms;
  SerialRig after_deadline{short_deadline};
  const auto opened = Clock::now();  // the card was opened before this
  std::this_thread::sleep_until(opened + short_deadline.operation_deadline);  // the subject: time
  executed = after_deadline.executed();
  start = Clock::now();
  const std::string error = read_or_error(*after_deadline.amp);
  const auto waited_past = Clock::now() - start;
  EXPECT_NE(error.find("time was up"), std::string::npos) << error;
  EXPECT_NE(error.find("not sent"), std::string::npos) << error;
  EXPECT_EQ(after_deadline.executed(), executed) << "nothing reaches the card past the deadline";
  EXPECT_LT(waited_past, 100ms);
  std::cout << "serial, a read past the deadline: 0 sends, "
            << std::chrono::duration_cast<std::chrono::milliseconds>(waited_past).count() << " ms\n";
}

// A lost read begun shortly before the deadline: its silence window is cut at the deadline.
// Judged against the deadline the card's opening set (Amp::bound()), not a time taken before
// the rig was built: on a loaded sanitizer host building it took long enough that a run
// ending 39 ms past the deadline measured 939 ms against a 900 ms limit.
TEST(OperationDeadline, TheSilenceWindowEndsAtTheDeadline) {
  ops::RetryPolicy retry;  // a 2 s window
  retry.operation_deadline = 700ms;
  SerialRig rig{retry};
  const auto deadline = rig.amp->bound();
  rig.stream->control("drop 1");
  EXPECT_NE(read_or_error(*rig.amp), "");
  const auto past = Clock::now() - deadline;  // negative: before it
  EXPECT_GE(past, -50ms) << "the window ended well before the deadline";
  EXPECT_LT(past, 200ms) << "the window ran past the deadline";
  std::cout << "serial, a lost read with a 700 ms deadline: ended "
            << std::chrono::duration_cast<std::chrono::milliseconds>(past).count() << " ms past it\n";
}

// Over Ethernet with the programs' own UDP waits (a packet with writes waits over all its
// attempts, up to seconds, backed off to 1 s each): every request lost on the network, a
// read begun within the deadline ends at it, and one past it sends nothing.
TEST(OperationDeadline, OverEthernetNoReplyWaitRunsPastItAndNothingIsSentAfter) {
  test::RunningBoard card;
  ethsim::FaultyNetwork network(card.address(), ethsim::NetworkFaults{});
  const eth::HostPort proxy = eth::parse_host_port(network.address());
  ops::RetryPolicy retry;
  retry.operation_deadline = 1500ms;
  ops::LinkSettings settings;
  const auto options = ops::timing::passthrough(settings, retry);  // the programs' waits
  auto udp = std::make_unique<eth::UdpClient>(proxy.ip, proxy.port, options.udp);
  const auto* client = udp.get();
  const auto opened_at = Clock::now();
  auto opened =
      open_eth(proxy, options, retry, std::make_unique<eth::FencedTransport>(std::move(udp), options.fence));
  ASSERT_EQ(read_or_error(*opened), "");

  network.set_faults(ethsim::NetworkFaults{.drop_share = 1.0, .requests = true, .replies = false});
  EXPECT_NE(read_or_error(*opened), "");
  const auto ended = Clock::now() - opened_at;
  EXPECT_LT(ended, retry.operation_deadline + 300ms) << "a reply wait ran past the deadline";

  const auto sent = client->stats().packets_sent;
  const std::string error = read_or_error(*opened);
  EXPECT_NE(error.find("time was up"), std::string::npos) << error;
  EXPECT_EQ(client->stats().packets_sent, sent) << "a packet was sent past the deadline";
  std::cout << "Ethernet, every request lost, a 1,500 ms deadline: the read ended "
            << std::chrono::duration_cast<std::chrono::milliseconds>(ended).count()
            << " ms after opening began; past it 0 packets\n";
}
