// SPDX-License-Identifier: GPL-2.0-or-later
#include "eth/batched_opening.hpp"

#include <algorithm>

#include "eth/errors.hpp"
#include "lbp/bytes.hpp"

namespace i20::eth {

namespace lbp16 = lbp::lbp16;
namespace hm2 = lbp::hm2;
namespace sslbp = lbp::hm2::sslbp;

namespace {

// HostMot2 keeps its IDROM at 0x400 with the module and pin tables behind it (IDROM,
// modules at +0x40, pins at +0x1C0): 1 KiB covers all three at their usual places.
constexpr std::size_t kUsualTablesBytes = 1024;

void add_block_reads(std::vector<lbp16::Command>& commands, std::uint32_t address, std::size_t bytes) {
  for (std::size_t done = 0; done < bytes;) {
    const std::size_t words = std::min<std::size_t>((bytes - done + 3) / 4, lbp16::kMaxCount);
    commands.push_back(
        lbp16::read_hm2(static_cast<std::uint16_t>(address + done), static_cast<unsigned>(words)));
    done += 4 * words;
  }
}

// The IDROM and its tables out of `block`, read at the usual address; false when the
// card's own pointers lead elsewhere.
bool tables_from(const lbp::Bytes& block, HostMot2Info& info) {
  if (!info.ident.valid() || info.ident.idrom_address != hm2::kUsualIdromAddress ||
      block.size() < hm2::Idrom::kBytes)
    return false;
  const lbp::ByteView all(block);
  const hm2::Idrom idrom = hm2::Idrom::parse(all.subspan(0, hm2::Idrom::kBytes));
  const std::size_t modules = hm2::kMaxModules * hm2::ModuleDescriptor::kBytes;
  const std::size_t pin_count = std::min<std::size_t>(idrom.io_width, hm2::kMaxPins);
  const std::size_t pins = pin_count * hm2::PinDescriptor::kBytes;
  if (idrom.offset_to_modules + modules > block.size() || idrom.offset_to_pins + pins > block.size())
    return false;
  info.idrom = idrom;
  info.modules = hm2::parse_modules(all.subspan(idrom.offset_to_modules, modules));
  info.pins = hm2::parse_pins(all.subspan(idrom.offset_to_pins, pins), pin_count);
  return true;
}

// A register's value from its reply bytes.
constexpr auto word = lbp::read_le32;

}  // namespace

BoardSurvey survey_board(Lbp16Transport& bus, std::span<const lbp16::Command> extra) {
  std::vector<lbp16::Command> commands{lbp16::read_board_info()};
  add_block_reads(commands, hm2::kCookieAddress, 16);
  const std::size_t first_table = commands.size();
  add_block_reads(commands, hm2::kUsualIdromAddress, kUsualTablesBytes);
  const std::size_t first_extra = commands.size();
  commands.insert(commands.end(), extra.begin(), extra.end());

  BoardSurvey survey;
  const auto resends = bus.stats().resends;
  const auto parts = bus.transact_counted(commands, Resend::IfReadOnly, survey.sent);
  survey.sent_once = bus.stats().resends == resends;
  survey.unarrived = bus.stats().unarrived;
  survey.replied_at = std::chrono::steady_clock::now();
  const auto board = lbp16::BoardInfo::parse(parts[0]);
  survey.identity = BoardIdentity{.card_name = board.card_name,
                                  .lbp16_version = board.lbp16_version,
                                  .firmware_version = board.firmware_version};
  survey.hostmot2.ident = hm2::IdentArea::parse(parts[1]);
  lbp::Bytes block;
  for (std::size_t i = first_table; i < first_extra; ++i)
    block.insert(block.end(), parts[i].begin(), parts[i].end());
  survey.extra_replies.assign(parts.begin() + static_cast<std::ptrdiff_t>(first_extra), parts.end());
  // Anything unusual (no cookie, an IDROM elsewhere) takes the reads that check and follow
  // the pointers, with their one-line errors.
  if (!tables_from(block, survey.hostmot2)) survey.hostmot2 = read_hostmot2(bus);
  return survey;
}

std::vector<Completion> run_sequence(SslbpPort& sslbp, std::span<const SslbpStep> steps) {
  const auto& regs = sslbp.port().registers;
  std::vector<Completion> out(steps.size());
  std::size_t trusted = 0;  // steps [0, trusted) have their results
  if (sslbp.timer_space() && steps.size() > 1) {
    // COMMAND as the first write finds it (SslbpPort::run says why): a busy one ignores the
    // write, and its DATA could be read as the first step's. Each later step's write follows
    // the read-back that found the one before it done, in the same packet.
    std::vector<lbp16::Command> packet{lbp16::read_hm2(regs.command)};
    std::vector<std::size_t> first_read;
    for (const SslbpStep& s : steps) {
      packet.push_back(lbp16::write_hm2(regs.command, s.command));
      const auto us = static_cast<std::uint16_t>(std::clamp<std::int64_t>(s.settle.count(), 1, 0xFFFF));
      packet.push_back(lbp16::write(lbp16::space::kTimers, kWaitMicrosecondsAddress, lbp16::Width::Bits16,
                                    lbp::to_le(us, 2), false));
      first_read.push_back(packet.size());
      packet.push_back(lbp16::read_hm2(regs.command));
      packet.push_back(lbp16::read_hm2(regs.data));
      for (std::uint16_t a : s.results) packet.push_back(lbp16::read_hm2(a));
    }
    try {
      const auto parts = sslbp.bus().transact(packet, Resend::Never);
      const bool idle_at_first_write = (word(parts[0]) & 0xFFFF) == 0;
      for (; idle_at_first_write && trusted < steps.size(); ++trusted) {
        const std::size_t at = first_read[trusted];
        if ((word(parts[at]) & 0xFFFF) != 0) break;
        Completion& c = out[trusted];
        c.data = static_cast<std::uint8_t>(word(parts[at + 1]));
        for (std::size_t i = 0; i < steps[trusted].results.size(); ++i)
          c.results.push_back(word(parts[at + 2 + i]));
        c.round_trips = trusted == 0 ? 1 : 0;
      }
      if (trusted < steps.size()) {
        // What followed a busy step was ignored, or ran in a race and left its DATA: from
        // the busy one on, the steps run again one at a time. So does a last step still
        // busy at its read-back: a later packet's DATA is ours only if no other host's
        // packet came between, which SslbpPort::run checks.
        sslbp.wait_idle();
      }
    } catch (const link::TimeoutError&) {
      // Lost: every step runs again one at a time with its own lost-reply handling (the
      // steps of a sequence are repeatable; the transport fences first).
      sslbp.wait_idle();
      trusted = 0;
    }
  }
  for (std::size_t i = trusted; i < steps.size(); ++i)
    out[i] = sslbp.run({}, steps[i].command, steps[i].results, /*repeatable=*/true, steps[i].settle);
  return out;
}

std::vector<std::uint8_t> read_locals(SslbpPort& sslbp, std::span<const std::uint16_t> addresses,
                                      bool stop_first) {
  const auto settle = sslbp.options().local_settle;
  std::vector<SslbpStep> steps;
  if (stop_first) steps.push_back(SslbpStep{.command = sslbp::stop(), .settle = settle});
  for (std::uint16_t a : addresses)
    steps.push_back(SslbpStep{.command = sslbp::read_local(a), .settle = settle});
  const auto done = run_sequence(sslbp, steps);
  std::vector<std::uint8_t> out;
  for (std::size_t i = stop_first ? 1 : 0; i < done.size(); ++i) out.push_back(done[i].data);
  return out;
}

SslbpParameters stop_and_read_parameters(SslbpPort& sslbp) {
  namespace param = sslbp::param;
  const std::uint16_t clock = param::kClock;
  const std::uint16_t addresses[] = {param::kInterfaceType,
                                     param::kWidth,
                                     param::kMajorVersion,
                                     param::kMinorVersion,
                                     param::kChannelStart,
                                     param::kChannelStride,
                                     param::kProcessorType,
                                     param::kChannels,
                                     clock,
                                     static_cast<std::uint16_t>(clock + 1),
                                     static_cast<std::uint16_t>(clock + 2),
                                     static_cast<std::uint16_t>(clock + 3)};
  const auto b = read_locals(sslbp, addresses, /*stop_first=*/true);
  SslbpParameters p;
  p.interface_type = b[0];
  p.width = b[1];
  p.version_major = b[2];
  p.version_minor = b[3];
  p.channel_start = b[4];
  p.channel_stride = b[5];
  p.processor_type = b[6];
  p.channels = b[7];
  for (unsigned i = 0; i < 4; ++i) p.clock_hz |= std::uint32_t{b[8 + i]} << (8 * i);  // little endian
  return p;
}

std::optional<std::uint16_t> baud_rate_address(const SslbpParameters& parameters, unsigned channel) {
  const unsigned address =
      parameters.channel_start + channel * parameters.channel_stride + sslbp::param::kBaudRateOffset;
  if (parameters.channel_start == 0 || address + 4 > sslbp::kLocalAddressMask + 1) return std::nullopt;
  return static_cast<std::uint16_t>(address);
}

}  // namespace i20::eth
