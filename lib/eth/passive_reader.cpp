// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/passive_reader.hpp"

#include <algorithm>
#include <thread>

#include "eth/errors.hpp"
#include "eth/running_host.hpp"
#include "hostmot2/hostmot2.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace hm2 = lbp::hm2;
using SteadyClock = std::chrono::steady_clock;

namespace {

// What the passive path puts between itself and the wire: every request is checked to
// hold reads only (a write is a bug here, refused before anything is sent), waits for its
// turn under the rate bound, and goes once.
class ReadOnlyPacedTransport final : public Lbp16Transport {
 public:
  ReadOnlyPacedTransport(std::unique_ptr<Lbp16Transport> inner, unsigned per_second)
      : inner_(std::move(inner)), pacer_(per_second) {}

  std::vector<lbp::Bytes> transact(std::span<const lbp16::Command> commands, Resend) override {
    check(commands);
    pacer_.wait_turn();
    return inner_->transact(commands, Resend::Never);
  }
  std::vector<lbp::Bytes> transact_counted(std::span<const lbp16::Command> commands, Resend,
                                           std::uint64_t& sent) override {
    check(commands);
    pacer_.wait_turn();
    return inner_->transact_counted(commands, Resend::Never, sent);
  }
  std::string describe() const override { return inner_->describe(); }
  TransportStats stats() const override { return inner_->stats(); }

 private:
  static void check(std::span<const lbp16::Command> commands) {
    for (const auto& c : commands)
      if (c.word.write) throw UsageError("internal error: the passive monitor was asked to send a write");
  }
  std::unique_ptr<Lbp16Transport> inner_;
  RequestPacer pacer_;
};

std::unique_ptr<Lbp16Transport> open_udp(const HostPort& host_port, const PassiveOptions& options) {
  const UdpOptions udp{
      .timeout = options.timeout,
      .max_timeout = std::max(options.timeout.get(), options.max_timeout.get()),
      .retries = 0u,
      .sequence_tags = false,  // the tag is a write to space 6 Scratch
  };
  return std::make_unique<UdpClient>(host_port.ip, host_port.port, udp);
}

std::uint32_t word32(const lbp::Bytes& bytes, std::size_t index) {
  return static_cast<std::uint32_t>(lbp::read_le(lbp::ByteView(bytes).subspan(4 * index, 4)));
}

std::uint32_t moved(std::uint16_t before, std::uint16_t after) {
  return static_cast<std::uint16_t>(after - before);  // 16-bit counters wrap
}

}  // namespace

RequestPacer::RequestPacer(unsigned per_second)
    : spacing_(std::chrono::duration_cast<SteadyClock::duration>(std::chrono::seconds(1)) /
               std::max(1u, per_second)) {}

void RequestPacer::wait_turn() {
  if (last_) std::this_thread::sleep_until(*last_ + spacing_);
  last_ = SteadyClock::now();
}

unsigned sserial_channels(const HostMot2Info& info, unsigned port) {
  unsigned channels = 0;
  for (const auto& pin : info.pins) {
    if (!hm2::is_sserial(pin.secondary_tag) || pin.secondary_unit != port) continue;
    if (pin.secondary_pin & 0x80) continue;  // outputs: TX and TXEN; RX is the input, pin = channel + 1
    const unsigned n = pin.secondary_pin & 0x0F;
    if (n >= 1 && n <= hm2::kMaxChannelsPerPort) channels = std::max(channels, n);
  }
  return channels == 0 ? hm2::kMaxChannelsPerPort : channels;
}

PassiveReader::PassiveReader(const HostPort& host_port, PassiveOptions options)
    : PassiveReader(open_udp(host_port, options), options) {}

PassiveReader::PassiveReader(std::unique_ptr<Lbp16Transport> bus, PassiveOptions options)
    : bus_(std::make_unique<ReadOnlyPacedTransport>(std::move(bus), options.max_requests_per_second)),
      options_(options) {
  survey_ = survey_board(*bus_);
  ports_ = survey_.hostmot2.sserial_ports();
  if (ports_.empty())
    throw DiscoveryError("the " + survey_.identity.card_name + " at " + bus_->describe() +
                         " has no SSERIAL port in its configuration: there are no 8I20s to watch");
  for (const auto& port : ports_) {
    const unsigned n = sserial_channels(survey_.hostmot2, port.index);
    channels_.push_back(n);
    const auto& r = port.registers;
    request_.push_back(lbp16::read_hm2(r.data));
    request_.push_back(lbp16::read_hm2(r.cs(0), n));  // consecutive channels, 4 bytes apart
    request_.push_back(lbp16::read_hm2(r.interface0(0), n));
    request_.push_back(lbp16::read_hm2(r.interface1(0), n));
  }
  request_.push_back(udp_counters_read());
}

PassiveSnapshot PassiveReader::read() {
  std::uint64_t sent = 0;
  const auto parts = bus_->transact_counted(request_, Resend::Never, sent);
  PassiveSnapshot s;
  s.at = SteadyClock::now();
  s.wall = std::chrono::system_clock::now();
  std::size_t part = 0;
  for (std::size_t p = 0; p < ports_.size(); ++p) {
    const auto data = word32(parts[part], 0);
    const auto& cs = parts[part + 1];
    const auto& if0 = parts[part + 2];
    const auto& if1 = parts[part + 3];
    part += 4;
    for (unsigned ch = 0; ch < channels_[p]; ++ch)
      s.channels.push_back(ProcessData{.port = ports_[p].index,
                                       .channel = ch,
                                       .cs = word32(cs, ch),
                                       .interface0 = word32(if0, ch),
                                       .interface1 = word32(if1, ch),
                                       .doit_failed = ((data >> ch) & 1u) != 0});
  }
  const auto counters = lbp16::words16(parts[part]);
  const std::uint16_t received = counters.front(), replied = counters.back();
  if (last_received_ && last_sent_) {
    // Since the previous counter read the card received our one request and sent the
    // previous reply's successor: one packet each way is ours.
    const std::uint32_t in = moved(*last_received_, received), out = moved(*last_sent_, replied);
    s.foreign_packets = (in > 1 ? in - 1 : 0) + (out > 1 ? out - 1 : 0);
  }
  last_received_ = received;
  last_sent_ = replied;
  return s;
}

}  // namespace i20::eth
