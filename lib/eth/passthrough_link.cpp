#include "eth/passthrough_link.hpp"

#include <algorithm>

#include "eth/errors.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace sslbp = lbp::hm2::sslbp;

namespace {

// Setup mode's serial rate when the firmware does not say (8I20 setup mode: 115200 8N1).
constexpr std::uint32_t kFallbackBaud = 115200;

}  // namespace

std::unique_ptr<SslbpPassthroughLink> SslbpPassthroughLink::open(const EthTarget& target,
                                                                 PassthroughOptions options) {
  auto bus = std::make_unique<UdpClient>(target.card.ip, target.card.port, options.udp);
  return std::make_unique<SslbpPassthroughLink>(std::move(bus), target, options);
}

SslbpPassthroughLink::SslbpPassthroughLink(std::unique_ptr<Lbp16Transport> bus, const EthTarget& target,
                                           PassthroughOptions options)
    : bus_(std::move(bus)), target_(target), options_(options) {
  card_ = identify(*bus_);
  const HostMot2Info info = read_hostmot2(*bus_);
  const SserialPort port = find_sserial_port(info, target_.sserial_port);
  port_ = std::make_unique<SslbpPort>(*bus_, port, card_.has_timer_space(), options_.sslbp);
  port_->stop_all();
  parameters_ = port_->read_parameters();
  if (parameters_.channels > 0 && target_.channel >= parameters_.channels)
    throw DiscoveryError(card_.card_name + " SSERIAL port " + std::to_string(port.index) + " has " +
                         std::to_string(parameters_.channels) + " channel(s), there is no channel " +
                         std::to_string(target_.channel));
  baud_ = port_->read_baud_rate(parameters_, target_.channel);
  start_setup();

  notes_.push_back("card " + card_.card_name + ", LBP16 version " + std::to_string(card_.lbp16_version) +
                   ", firmware version " + std::to_string(card_.firmware_version) + ", HostMot2 " +
                   info.idrom.board_name);
  notes_.push_back("SSLBP " + parameters_.version() + " on SSERIAL port " + std::to_string(port.index) +
                   " (COMMAND at " + lbp::hex_value(port.registers.command, 8) + "), " +
                   std::to_string(parameters_.channels) + " channel(s), remote baud " +
                   (baud_ ? std::to_string(baud_) : std::string("unknown")));
  notes_.push_back("remote " + remote_.name + " unit " + lbp::hex_value(remote_.unit_number, 8));
  notes_.push_back(card_.has_timer_space() ? "passthrough waits inside the packet (LBP16 WaituS)"
                                           : "no LBP16 timer space: passthrough polls COMMAND");
}

SslbpPassthroughLink::~SslbpPassthroughLink() {
  try {
    port_->stop_all();
  } catch (...) {
    // Best effort: the card may be gone; leaving SSLBP in setup mode is harmless.
  }
}

void SslbpPassthroughLink::start_setup() {
  const std::uint8_t mask = target_.channel_mask();
  port_->stop_all();
  const std::uint8_t failed = port_->start_setup(mask);
  const ChannelRegisters regs = port_->read_channels(mask).front();
  remote_ = RemoteInfo{.name = regs.name(), .unit_number = regs.interface0, .cs = regs.cs};
  if (failed & mask)
    throw DiscoveryError("no remote answered on " + describe() + " at setup start (CS " +
                         lbp::hex_value(regs.cs, 8) + ": " + regs.status().describe() +
                         "); check the cable and the 8I20's logic power");
  if (options_.require_8i20 && regs.interface1 != sslbp::kName8i20)
    throw DiscoveryError("the remote on " + describe() + " reports itself as '" + regs.name() +
                         "', not an 8I20");
}

void SslbpPassthroughLink::resync() {
  if (!port_->wait_idle()) {
    ++stats_.restarts;
    start_setup();
  }
  needs_resync_ = false;
}

std::chrono::microseconds SslbpPassthroughLink::settle_for(const PassthroughStep& step) const {
  const std::uint64_t baud = baud_ ? baud_ : kFallbackBaud;
  const std::uint64_t characters = step.wire_bytes + options_.turnaround_characters;
  auto us = std::chrono::microseconds(characters * 10 * 1'000'000 / baud) + options_.overhead;
  if (step.data_write && nv_mode_ != 0) us += options_.nv_write_time;
  return us;
}

std::vector<lbp::Bytes> SslbpPassthroughLink::execute(std::span<const lbp::Command> batch) {
  if (needs_resync_) resync();
  std::vector<lbp::Bytes> replies;
  replies.reserve(batch.size());
  for (std::size_t i = 0; i < batch.size(); ++i) {
    PassthroughStep step;
    try {
      step = plan_passthrough(batch[i]);
    } catch (const link::UnsupportedCommand& e) {
      throw link::UnsupportedCommand(e.what(), i);
    }
    const Completion c = execute_step(step, i);
    if (c.data & target_.channel_mask()) raise_transfer_error(batch[i], c.results[1], i);
    if (step.nv_access_mode) nv_mode_ = *step.nv_access_mode;
    replies.push_back(reply_from_interface0(c.results[0], step.reply_bytes));
  }
  return replies;
}

Completion SslbpPassthroughLink::execute_step(const PassthroughStep& step, std::size_t index) {
  const unsigned ch = target_.channel;
  const auto& regs = port_->port().registers;
  std::vector<lbp16::Command> before;
  if (step.interface0) before.push_back(lbp16::write_hm2(regs.interface0(ch), *step.interface0));
  before.push_back(lbp16::write_hm2(regs.cs(ch), step.cs));
  const std::uint16_t results[] = {regs.interface0(ch), regs.cs(ch)};

  Completion c;
  try {
    c = port_->run(before, sslbp::doit(target_.channel_mask()), results, step.repeatable, settle_for(step));
  } catch (const link::TimeoutError& e) {
    needs_resync_ = true;
    throw link::TimeoutError(e.what(), index);
  } catch (const BadReplyError& e) {
    needs_resync_ = true;
    throw BadReplyError(e.what(), index);
  } catch (const link::LinkError& e) {
    needs_resync_ = true;
    throw link::LinkError(e.what(), index);
  }
  ++stats_.commands;
  stats_.round_trips += c.round_trips;
  stats_.max_round_trips = std::max<std::uint64_t>(stats_.max_round_trips, c.round_trips);
  return c;
}

void SslbpPassthroughLink::raise_transfer_error(const lbp::Command& command, std::uint32_t cs,
                                                std::size_t index) const {
  const sslbp::ChannelStatus status{cs};
  const std::string message = "the remote on " + describe() + " did not complete LBP command " +
                              lbp::to_hex(command.bytes) + " (SSLBP CS " + lbp::hex_value(cs, 8) + ": " +
                              status.describe() + ")";
  if (status.timed_out()) throw link::TimeoutError(message, index);
  if (status.crc_error()) throw link::CrcError(message, index);
  throw SslbpError(message, index);
}

}  // namespace i20::eth
