// SPDX-License-Identifier: GPL-2.0-or-later
// PassthroughPort's lifecycle: opening (the running-host check, setup start), resync after
// a restart, the check for another host's packets, closing, the links and the accessors.
// Packing commands into packets and replaying them: passthrough_packing.cpp. Combining the
// links' batches: command_combiner.cpp.
#include "eth/passthrough_port.hpp"

#include <algorithm>

#include "eth/batched_opening.hpp"
#include "eth/errors.hpp"
#include "eth/fenced_transport.hpp"
#include "eth/passthrough_work.hpp"
#include "eth/running_host.hpp"
#include "lbp/bytes.hpp"
#include "lbp/local.hpp"
#include "link/wait_bound.hpp"

namespace i20::eth {

using namespace passthrough_detail;  // lbp16, sslbp, microseconds, kFallbackBaud, bit, channels_of

namespace {

// How long a setup start takes: SSLBP asks each remote its name (four local reads) and its
// unit number (one 4-byte read), the channels side by side, at the slowest channel's baud
// (setup mode's 115200 where the rate is not known yet).
microseconds setup_start_time(const std::vector<std::uint32_t>& bauds, const std::vector<unsigned>& channels,
                              const PassthroughOptions& options) {
  std::uint64_t slowest = 0;
  for (unsigned ch : channels) {
    const std::uint64_t baud = bauds[ch] ? bauds[ch] : kFallbackBaud;
    slowest = slowest ? std::min(slowest, baud) : baud;
  }
  const std::uint64_t characters =
      4 * (2 + options.turnaround_characters) + (3 + 4 + options.turnaround_characters);
  return microseconds(characters * 10 * 1'000'000 / std::max<std::uint64_t>(slowest, 1)) + options.overhead;
}

// ---- a link to one channel ----------------------------------------------------------------

// Holds the port (and so its combiner) alive.
class ChannelLink final : public link::Link {
 public:
  ChannelLink(std::shared_ptr<PassthroughPort> port, CommandCombiner& combiner, unsigned channel)
      : port_(std::move(port)), combiner_(combiner), channel_(channel) {
    combiner_.attach();
  }
  ~ChannelLink() override { combiner_.detach(); }
  ChannelLink(const ChannelLink&) = delete;
  ChannelLink& operator=(const ChannelLink&) = delete;

  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override {
    return combiner_.execute(channel_, batch);
  }
  std::string describe() const override { return port_->describe(channel_); }
  std::size_t max_data_bytes() const override { return 4; }  // INTERFACE0 is 32 bits wide
  std::vector<std::string> notes() const override { return port_->notes(); }

 private:
  std::shared_ptr<PassthroughPort> port_;
  CommandCombiner& combiner_;
  unsigned channel_;
};

}  // namespace

// ---- opening and closing ------------------------------------------------------------------

std::shared_ptr<PassthroughPort> PassthroughPort::open(const HostPort& host_port, unsigned sserial_port,
                                                       std::uint8_t channel_mask,
                                                       PassthroughOptions options) {
  std::shared_ptr<Lbp16Transport> bus = std::make_unique<FencedTransport>(
      std::make_unique<UdpClient>(host_port.ip, host_port.port, options.udp), options.fence);
  return open(std::move(bus), sserial_port, channel_mask, std::move(options));
}

std::shared_ptr<PassthroughPort> PassthroughPort::open(std::shared_ptr<Lbp16Transport> card,
                                                       unsigned sserial_port, std::uint8_t channel_mask,
                                                       PassthroughOptions options) {
  for (unsigned attempt = 1;; ++attempt) {
    try {
      return std::make_shared<PassthroughPort>(card, sserial_port, channel_mask, options);
    } catch (const link::TimeoutError&) {  // a datagram lost on the way, or its reply
      if (attempt >= options.opening_attempts) throw;
    } catch (const LatePacketError&) {  // one given up on that arrived after all
      if (attempt >= options.opening_attempts) throw;
    }
    // The next try's first exchange asks for time left (WaitBound) and fences first. A reply
    // of the wrong shape, SSLBP's own error, another host and the time being up end it.
  }
}

std::shared_ptr<Lbp16Transport> PassthroughPort::board_transport(const HostPort& host_port,
                                                                 const UdpOptions& options,
                                                                 const FenceOptions& fence) {
  // The ledger of arrivals under the lock: it must see every port's packets as ours.
  return std::make_shared<SharedTransport>(std::make_unique<FencedTransport>(
      std::make_unique<UdpClient>(host_port.ip, host_port.port, options), fence));
}

PassthroughPort::PassthroughPort(std::shared_ptr<Lbp16Transport> bus, unsigned sserial_port,
                                 std::uint8_t channel_mask, PassthroughOptions options)
    : bus_(std::move(bus)), sserial_port_(sserial_port), mask_(channel_mask), options_(std::move(options)) {
  if (mask_ == 0) throw UsageError("a passthrough port needs at least one channel");
  // Identification, the IDROM and the running-host watch's first counters: one request.
  const lbp16::Command counters = udp_counters_read();
  const BoardSurvey survey = survey_board(*bus_, std::span(&counters, 1));
  board_ = survey.identity;
  const HostMot2Info& info = survey.hostmot2;
  const CounterSample first{.reply = survey.extra_replies.front(),
                            .sent = survey.sent,
                            .at = survey.replied_at,
                            .sent_once = survey.sent_once,
                            .unarrived = survey.unarrived};
  // One COMMAND sample, with the last counter read at the end of the window: the whole
  // command stays within issue 18's 8 requests. The counters decide (host_is_running); a
  // busy COMMAND only names what was seen, and a sample halfway changed no decision. A host
  // that starts after the window owns the port from its first packet
  // (refuse_if_another_host_took_the_port); one that shows itself before our setup start is
  // watched again first (below). Samples cannot share a request: a card that waits between
  // them (WaituS) serves no other host meanwhile.
  RunningHostCheck watch = options_.running_host;
  watch.command_samples = 1;
  board_name_ = info.idrom.board_name;
  const SserialPort port = find_sserial_port(info, sserial_port_);
  sslbp_ = std::make_unique<SslbpPort>(*bus_, port, board_.has_timer_space(), options_.sslbp);
  activity_ =
      require_no_running_host(*bus_, std::span(&port, 1), watch,
                              "stop SSERIAL port " + std::to_string(port.index) + " for setup mode", first);
  last_received_ = activity_.last_received;
  missing_ours_ = 0;
  sent_at_last_ = activity_.sent_at_last;
  const std::uint64_t foreign_at_watch = bus_->stats().foreign_arrivals;
  parameters_ = stop_and_read_parameters(*sslbp_);
  // A host that started after the watch's last counter read (its stop, its polls) shows in
  // the count the transport reads first in the parameters' request, for no packet more.
  // Its start may follow at any moment, and ours would swallow it or re-mode its channel
  // after it: watch again before the setup start. A repeated datagram of ours shows no host.
  if (bus_->stats().foreign_arrivals != foreign_at_watch && !options_.running_host.take_over) {
    activity_ = require_no_running_host(*bus_, std::span(&port, 1), options_.running_host,
                                        "setup-start SSERIAL port " + std::to_string(port.index) +
                                            " (another host talked to the card after the watch)");
    last_received_ = activity_.last_received;
    sent_at_last_ = activity_.sent_at_last;
  }
  for (unsigned ch : channels_of(mask_)) {
    if (parameters_.channels > 0 && ch >= parameters_.channels)
      throw DiscoveryError(board_.card_name + " SSERIAL port " + std::to_string(port.index) + " has " +
                           std::to_string(parameters_.channels) + " channel(s), there is no channel " +
                           std::to_string(ch));
  }
  start_setup();

  notes_.push_back("card " + board_.card_name + ", LBP16 version " + std::to_string(board_.lbp16_version) +
                   ", firmware version " + std::to_string(board_.firmware_version) + ", HostMot2 " +
                   board_name_);
  notes_.push_back("SSLBP " + parameters_.version() + " on SSERIAL port " + std::to_string(port.index) +
                   " (COMMAND at " + lbp::hex_value(port.registers.command, 8) + "), " +
                   std::to_string(parameters_.channels) + " channel(s)");
  notes_.push_back((options_.running_host.take_over ? "take-over asked for; " : std::string()) +
                   activity_.describe());
  for (unsigned ch : channels_of(mask_)) {
    const RemoteInfo& r = remotes_[ch];
    std::string note = "ch " + std::to_string(ch) + ": " + r.name + " unit " +
                       lbp::hex_value(r.unit_number, 8) + ", remote baud " +
                       (bauds_[ch] ? std::to_string(bauds_[ch]) : std::string("unknown"));
    notes_.push_back(note);
  }
  notes_.push_back(board_.has_timer_space()
                       ? "passthrough batches DOITs and waits inside the packet (LBP16 WaituS)"
                       : "no LBP16 timer space: one DOIT per packet, COMMAND polled");
  stats_ = PassthroughStats{};  // the figures describe execute() traffic, not the opening
}

PassthroughPort::~PassthroughPort() {
  const link::WaitBound bounded(std::chrono::steady_clock::now() + options_.close_budget.get());
  try {
    if (another_host_runs_the_port()) return;  // its machine runs on that port: leave it be
    sslbp_->stop_all();
  } catch (...) {
    // Best effort: the card may be gone; leaving SSLBP in setup mode drives no motor.
  }
}

// Asked only when another host showed itself during the session (a stop costs nothing to
// check otherwise): a host that started normal mode while we ran owns the port now, and a
// stop would drop every axis on it. A take-over stops it anyway, as asked.
bool PassthroughPort::another_host_runs_the_port() {
  const bool seen = other_host_seen_ || bus_->stats().foreign_arrivals > 0;
  if (!seen || options_.running_host.take_over) return false;
  const HostActivity now = observe_host_activity(*bus_, std::span(&sslbp_->port(), 1), options_.running_host);
  return host_is_running(now, options_.running_host);
}

// A host that showed itself during the session (its stop, its start, its DOITs) owns the
// port from then on: any command of ours could land while its start runs, and SSLBP ignores a
// command written while it is busy, so its start could be lost and its machine left in our
// setup mode. Read-only: it watches the card, and refuses everything after (Refused: the
// use case does not resend it). A foreign packet that was a repeated datagram of ours shows
// no host, and the session goes on.
void PassthroughPort::refuse_if_another_host_took_the_port() {
  if (!other_host_seen_ || options_.running_host.take_over) return;
  require_no_running_host(*bus_, std::span(&sslbp_->port(), 1), options_.running_host,
                          "send more commands to SSERIAL port " + std::to_string(sserial_port_) +
                              " (another host started on it during this session)");
}

void PassthroughPort::start_setup() {
  const auto channels = channels_of(mask_);
  const auto& registers = sslbp_->port().registers;
  // One sequence, one request where the card has the timer space: the stop, the remotes'
  // baud rates, the setup start, and the channels' registers as the start left them.
  std::vector<SslbpStep> steps{{.command = sslbp::stop(), .settle = options_.sslbp.local_settle}};
  std::vector<std::pair<unsigned, std::size_t>> baud_steps;  // channel, its first step
  for (unsigned ch : channels)
    if (const auto at = baud_rate_address(parameters_, ch)) {
      baud_steps.emplace_back(ch, steps.size());
      for (unsigned i = 0; i < 4; ++i)
        steps.push_back({.command = sslbp::read_local(static_cast<std::uint16_t>(*at + i)),
                         .settle = options_.sslbp.local_settle});
    }
  std::vector<std::uint16_t> read_back;
  for (unsigned ch : channels)
    for (std::uint16_t a :
         {registers.cs(ch), registers.interface0(ch), registers.interface1(ch), registers.interface2(ch)})
      read_back.push_back(a);
  steps.push_back({.command = sslbp::start_setup(mask_),
                   .settle = setup_start_time(bauds_, channels, options_),
                   .results = read_back});
  const auto done = run_sequence(*sslbp_, steps);
  for (const auto& [ch, at] : baud_steps) {
    std::uint32_t baud = 0;
    for (unsigned i = 0; i < 4; ++i) baud |= std::uint32_t{done[at + i].data} << (8 * i);
    bauds_[ch] = baud;
  }
  std::uint8_t failed = done.back().data;
  std::vector<ChannelRegisters> regs;
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const auto& r = done.back().results;
    regs.push_back(ChannelRegisters{.cs = r.at(4 * i),
                                    .interface0 = r.at(4 * i + 1),
                                    .interface1 = r.at(4 * i + 2),
                                    .interface2 = r.at(4 * i + 3)});
  }
  // In a take-over the other host's DOITs can land inside ours and fail a channel that is there.
  for (unsigned attempt = 1; failed != 0 && attempt < options_.running_host.setup_start_attempts();
       ++attempt) {
    sslbp_->stop_all();
    failed = sslbp_->start_setup(mask_);
    regs = sslbp_->read_channels(mask_);
  }
  for (std::size_t i = 0; i < channels.size(); ++i) {
    const unsigned ch = channels[i];
    remotes_[ch] = RemoteInfo{.name = regs[i].name(), .unit_number = regs[i].interface0, .cs = regs[i].cs};
    if (failed & bit(ch))
      throw DiscoveryError("no remote answered on " + describe(ch) + " at setup start (CS " +
                           lbp::hex_value(regs[i].cs, 8) + ": " + regs[i].status().describe() +
                           "); check the cable and the 8I20's logic power");
    if (options_.require_8i20 && regs[i].interface1 != sslbp::kName8i20)
      throw DiscoveryError("the remote on " + describe(ch) + " reports itself as '" + regs[i].name() +
                           "', not an 8I20");
  }
}

// Each 8I20's NV access mode (0xCC), in one DOIT, after a restart mid-session: known modes
// let NV mode changes share packets with other commands. (At the opening the modes are
// learnt from the device layer's own first reads of 0xCC and 0xCA instead: see finish().)
void PassthroughPort::read_nv_modes() {
  const auto channels = channels_of(mask_);
  const lbp::Command query = lbp::local_read(lbp::local::kGetNvAccess);
  std::vector<Channel> work;
  const std::vector<std::optional<std::uint8_t>> asked = nv_modes_;
  for (unsigned ch : channels) {
    nv_modes_[ch].reset();
    Channel c{.channel = ch, .commands = std::span(&query, 1), .steps = {plan_passthrough(query)}};
    c.mode_before.assign(2, std::nullopt);
    work.push_back(std::move(c));
  }
  run(work);
  for (const Channel& c : work) {
    if (c.error || c.replies.empty()) continue;
    const std::uint8_t found = c.replies.front().at(0);
    // Between packets the card is in normal access by design (bracket_modes), so normal
    // access found there does not undo an NV mode the tool's commands asked for; the next
    // packet sets it again.
    const auto before = asked[c.channel];
    nv_modes_[c.channel] = (found == 0 && before && *before != 0) ? *before : found;
  }
}

// After a failed exchange: SSLBP still busy (a DOIT that never finished), or a channel no
// longer in setup mode (the card reset and its ports came back stopped), is started again.
// A restart that finds no 8I20 answering is a silent card (TimeoutError), which the use
// case may wait for, not a wrong target.
void PassthroughPort::resync() {
  if (!sslbp_->wait_idle() || port_left_setup_) {
    // Restarting is a start: the running-host rule applies again.
    ++stats_.restarts;
    HostActivity seen;
    try {
      seen =
          require_no_running_host(*bus_, std::span(&sslbp_->port(), 1), options_.running_host,
                                  "restart SSERIAL port " + std::to_string(sserial_port_) + " in setup mode");
    } catch (const RunningHostError&) {
      other_host_seen_ = true;
      throw;
    }
    last_received_ = seen.last_received;
    sent_at_last_ = seen.sent_at_last;
    missing_ours_ = 0;
    try {
      start_setup();
    } catch (const DiscoveryError& e) {
      throw link::TimeoutError(std::string("restarting SSERIAL port ") + std::to_string(sserial_port_) +
                               " in setup mode: " + e.what());
    }
    port_left_setup_ = false;
    read_nv_modes();
  }
  needs_resync_ = false;
}

// ---- another host on the card ------------------------------------------------------------

void PassthroughPort::require_no_foreign_packets(std::uint16_t received, std::uint64_t sent) {
  const std::int64_t moved = static_cast<std::uint16_t>(received - last_received_);
  const auto ours = static_cast<std::int64_t>(sent - sent_at_last_);
  last_received_ = received;
  sent_at_last_ = sent;
  // Packets of ours that had not arrived at the last look (an unanswered one, a lost one)
  // may arrive since: they are not another host's.
  const std::int64_t missing = static_cast<std::int64_t>(missing_ours_) + ours - moved;
  missing_ours_ = static_cast<std::uint64_t>(std::max<std::int64_t>(missing, 0));
  if (missing >= 0) return;
  other_host_seen_ = true;
  throw ForeignHostError(
      "another host sent " + std::to_string(-missing) + " packet(s) to the card on " + describe() +
      " during this exchange (LinuxCNC running?): its DOITs run the passthrough's commands "
      "too, so the results were discarded; stop that host and run the command again");
}

void PassthroughPort::require_undisturbed(std::uint64_t foreign_before) {
  const std::uint64_t foreign = bus_->stats().foreign_arrivals - foreign_before;
  if (foreign == 0) return;
  other_host_seen_ = true;
  throw ForeignHostError("the card on " + describe() + " received " + std::to_string(foreign) +
                         " packet(s) that were not ours between a DOIT and the read of its result "
                         "(another host, or a repeated datagram): the results were discarded");
}

// ---- accessors ----------------------------------------------------------------------------

const RemoteInfo& PassthroughPort::remote(unsigned channel) const {
  if (channel >= kMaxChannels || !(mask_ & bit(channel)))
    throw UsageError("channel " + std::to_string(channel) + " is not part of " + describe());
  return remotes_[channel];
}

std::uint32_t PassthroughPort::baud(unsigned channel) const {
  return bauds_.at(channel);
}

PassthroughStats PassthroughPort::stats() const {
  std::lock_guard lock(execute_mutex_);
  PassthroughStats s = stats_;
  s.slack = slack_;
  return s;
}

TransportStats PassthroughPort::transport_stats() const {
  std::lock_guard lock(execute_mutex_);
  return bus_->stats();
}

std::string PassthroughPort::describe() const {
  return "eth " + bus_->describe() + " port " + std::to_string(sserial_port_);
}

std::string PassthroughPort::describe(unsigned channel) const {
  std::string s = "eth " + bus_->describe();
  if (sserial_port_ != 0) s += " port " + std::to_string(sserial_port_);
  return s + " ch " + std::to_string(channel);
}

std::unique_ptr<link::Link> PassthroughPort::link(unsigned channel) {
  remote(channel);  // UsageError for a channel outside the mask
  return std::make_unique<ChannelLink>(shared_from_this(), combiner_, channel);
}

}  // namespace i20::eth
