// SPDX-License-Identifier: GPL-2.0-or-later
#include "ethsim/sslbp_engine.hpp"

#include <algorithm>

#include "lbp/crc8.hpp"
#include "error/error.hpp"
#include "lbp/header.hpp"
#include "lbp/local.hpp"

namespace i20::ethsim {

namespace sslbp = lbp::hm2::sslbp;
namespace reg = lbp::hm2::sserial_reg;
using Status = sslbp::ChannelStatus;

namespace {

// CS byte 2 ("communication state code, debug only"): what the channel is doing.
constexpr std::uint8_t kStateStopped = 0x00;
constexpr std::uint8_t kStateNormal = 0x09;
constexpr std::uint8_t kStateSetup = 0x0F;

// UNITNUMBER's public address (docs/facts.md section 2): SSLBP reads it at start.
constexpr std::uint16_t kUnitNumberAddress = 2344;

// Bound on catch-up chatter after a long quiet spell (the host was away for seconds).
constexpr unsigned kMaxChatterSteps = 64;

void put_le32(std::array<std::uint8_t, 1024>& local, std::size_t at, std::uint32_t value) {
  for (unsigned i = 0; i < 4; ++i) local[at + i] = static_cast<std::uint8_t>(value >> (8 * i));
}

std::vector<unsigned> channels_in(std::uint32_t mask) {
  std::vector<unsigned> out;
  for (unsigned ch = 0; ch < 8; ++ch)
    if (mask & (1u << ch)) out.push_back(ch);
  return out;
}

}  // namespace

SslbpEngine::SslbpEngine(SslbpConfig config, std::vector<std::unique_ptr<RemoteLbpDevice>> remotes,
                         Clock::time_point now)
    : config_(config), now_(now) {
  if (config_.channels == 0 || config_.channels > lbp::hm2::kMaxChannelsPerPort)
    throw UsageError("an SSLBP port has 1 to 8 channels, not " + std::to_string(config_.channels));
  if (remotes.size() != config_.channels)
    throw UsageError("SSLBP port with " + std::to_string(config_.channels) + " channels given " +
                     std::to_string(remotes.size()) + " remote slots");
  channels_.resize(config_.channels);
  for (unsigned ch = 0; ch < config_.channels; ++ch) channels_[ch].remote = std::move(remotes[ch]);

  local_[sslbp::param::kInterfaceType] = config_.interface_type;
  local_[sslbp::param::kWidth] = static_cast<std::uint8_t>(config_.channels);
  local_[sslbp::param::kMajorVersion] = config_.version_major;
  local_[sslbp::param::kMinorVersion] = config_.version_minor;
  local_[sslbp::param::kChannelStart] = kSimChannelStart;
  local_[sslbp::param::kChannelStride] = kSimChannelStride;
  local_[sslbp::param::kProcessorType] = config_.processor_type;
  local_[sslbp::param::kChannels] = static_cast<std::uint8_t>(config_.channels);
  put_le32(local_, sslbp::param::kClock, config_.clock_hz);
  for (unsigned ch = 0; ch < config_.channels; ++ch)
    put_le32(local_, kSimChannelStart + ch * kSimChannelStride + sslbp::param::kBaudRateOffset, config_.baud);
}

std::uint32_t SslbpEngine::read(unsigned r, unsigned channel, Clock::time_point now) {
  advance(now);
  if (r == reg::kCommand) return in_reset_ ? reset_command_ : (pending_ ? pending_->command : 0);
  if (r == reg::kData) return data_;
  if (channel >= channels_.size()) return 0;
  const Registers& card = channels_[channel].card;
  switch (r) {
    case reg::kCs: return card.cs;
    case reg::kInterface0: return card.interface0;
    case reg::kInterface1: return card.interface1;
    case reg::kInterface2: return card.interface2;
    default: return 0;
  }
}

void SslbpEngine::write(unsigned r, unsigned channel, std::uint32_t value, Clock::time_point now) {
  advance(now);
  if (r == reg::kCommand) return execute(value & 0xFFFF, now_);
  if (r == reg::kData) {
    data_ = value & 0xFF;
    return;
  }
  if (channel >= channels_.size()) return;
  Registers& host = channels_[channel].host;
  switch (r) {
    case reg::kCs: host.cs = value; break;
    case reg::kInterface0: host.interface0 = value; break;
    case reg::kInterface1: host.interface1 = value; break;
    case reg::kInterface2: host.interface2 = value; break;
    default: break;
  }
}

void SslbpEngine::advance(Clock::time_point now) {
  now_ = std::max(now_, now);
  if (pending_ && now_ >= pending_->done) complete();
  if (pending_) return;  // the processor is busy with the host's command: no chatter
  for (Channel& ch : channels_) {
    if (!ch.remote) continue;
    if (ch.mode == ChannelMode::Normal && !ch.doit_seen) chatter(ch, now_);
    ch.remote->advance(now_);
  }
}

void SslbpEngine::chatter(Channel& ch, Clock::time_point now) {
  // Cookie reads keep the 8I20's watchdog fed until the host's first DOIT (manual,
  // "8I20 DEVICE SPECIFIC SETUP").
  for (unsigned step = 0; now - ch.last_traffic >= config_.chatter_period; ++step) {
    Clock::time_point t = ch.last_traffic + config_.chatter_period;
    if (step >= kMaxChatterSteps) t = now;
    ++stats_.chatter;
    transfer(ch, lbp::Bytes{lbp::local::kGetCookie}, 1, t);  // moves last_traffic past t
  }
}

void SslbpEngine::power_on_reset(Clock::time_point now) {
  execute(sslbp::kReset, now);
  in_reset_ = false;
  data_ = 0;
}

void SslbpEngine::complete() {
  Pending p = std::move(*pending_);
  pending_.reset();
  if (p.data) data_ = *p.data;
  for (std::size_t ch = 0; ch < channels_.size(); ++ch)
    if (p.results[ch]) channels_[ch].card = *p.results[ch];
}

void SslbpEngine::execute(std::uint32_t command, Clock::time_point now) {
  if (command & sslbp::kReset) {
    // Held in reset: every channel stops and nothing runs until bit 14 is released.
    in_reset_ = true;
    reset_command_ = command;
    pending_.reset();
    Pending p;
    p.results.resize(channels_.size());
    stop(0, p);
    for (std::size_t ch = 0; ch < channels_.size(); ++ch) channels_[ch].card = *p.results[ch];
    return;
  }
  in_reset_ = false;
  if (pending_) {
    ++stats_.ignored_while_busy;
    return;
  }
  ++stats_.commands;
  Pending p;
  p.command = command;
  p.results.resize(channels_.size());
  Clock::time_point t = now + config_.processing;
  const std::uint8_t mask = command & sslbp::kChannelMask;

  if (command & sslbp::kRequest) {
    const std::uint16_t address = command & sslbp::kLocalAddressMask;
    if (command & sslbp::kWrite)
      local_[address] = static_cast<std::uint8_t>(data_);
    else
      p.data = local_[address];
  } else if (command & (sslbp::kDoit | sslbp::kStart)) {
    const bool is_doit = (command & sslbp::kDoit) != 0;
    const std::uint32_t type = command & sslbp::kTypeMask;
    if (!is_doit && type == 0) {
      stop(mask, p);
    } else {
      if (is_doit) ++stats_.doits;
      std::uint8_t failed = 0;
      Clock::time_point end = t;
      for (unsigned index : channels_in(mask)) {
        if (index >= channels_.size()) {
          failed |= static_cast<std::uint8_t>(1u << index);
          continue;
        }
        Channel& ch = channels_[index];
        Registers out = ch.card;
        Clock::time_point tc = t;  // channels run side by side
        bool ok = false;
        if (is_doit)
          ok = doit(ch, out, tc);
        else if (type == (sslbp::kStartNormal & sslbp::kTypeMask))
          ok = start(ch, ChannelMode::Normal, out, tc);
        else if (type == (sslbp::kStartSetup & sslbp::kTypeMask))
          ok = start(ch, ChannelMode::Setup, out, tc);
        if (!ok) failed |= static_cast<std::uint8_t>(1u << index);
        p.results[index] = out;
        end = std::max(end, tc);
      }
      p.data = failed;
      t = end;
    }
  }
  p.done = t;
  pending_ = std::move(p);
  if (pending_->done <= now_) complete();
}

void SslbpEngine::stop(std::uint8_t mask, Pending& p) {
  for (std::size_t index = 0; index < channels_.size(); ++index) {
    if (mask != 0 && !(mask & (1u << index))) continue;
    Channel& ch = channels_[index];
    ch.mode = ChannelMode::Stopped;
    ch.errors = 0;  // the error byte is "cleared only by stop"
    ch.doit_seen = false;
    Registers out = ch.card;
    out.cs = 0;
    p.results[index] = out;
  }
  p.data = 0;
}

std::uint32_t SslbpEngine::status_word(const Channel& ch, std::uint8_t status) const {
  const std::uint8_t state = ch.mode == ChannelMode::Normal  ? kStateNormal
                             : ch.mode == ChannelMode::Setup ? kStateSetup
                                                             : kStateStopped;
  return std::uint32_t{ch.remote_mode} << 24 | std::uint32_t{state} << 16 | std::uint32_t{status} << 8 |
         ch.errors;
}

std::optional<lbp::Bytes> SslbpEngine::transfer(Channel& ch, const lbp::Bytes& command,
                                                std::size_t reply_bytes, Clock::time_point& t) {
  lbp::Bytes framed = command;
  framed.push_back(lbp::crc8(command));
  ++stats_.remote_exchanges;
  const Exchange ex = ch.remote->exchange(framed, reply_bytes + 1, t, config_.remote_timeout);
  t = std::max(t, ex.done) + config_.processing;
  ch.last_traffic = t;
  std::uint8_t error = 0;
  if (ex.reply.size() < reply_bytes + 1)
    error = Status::kTimeoutError;
  else if (ex.reply.size() > reply_bytes + 1)
    error = Status::kExtraCharacter;
  else if (lbp::crc8(ex.reply) != 0)
    error = Status::kCrcError;
  if (error) {
    ch.errors |= error;
    ++stats_.remote_failures;
    return std::nullopt;
  }
  return lbp::Bytes(ex.reply.begin(), ex.reply.end() - 1);
}

bool SslbpEngine::start(Channel& ch, ChannelMode mode, Registers& out, Clock::time_point& t) {
  ch.mode = ChannelMode::Stopped;
  ch.remote_mode = 0;
  out = Registers{};
  if (!ch.remote) {
    ch.errors |= Status::kTimeoutError;
    t += config_.remote_timeout;
    out.cs = status_word(ch, Status::kNotReady | Status::kNoRemoteId);
    return false;
  }
  std::uint32_t name = 0;
  for (unsigned i = 0; i < 4; ++i) {
    const auto c = transfer(ch, lbp::Bytes{static_cast<lbp::Byte>(lbp::local::kGetCardName0 + i)}, 1, t);
    if (!c) {
      out.cs = status_word(ch, Status::kNotReady | Status::kNoRemoteId);
      return false;
    }
    name |= std::uint32_t{c->front()} << (8 * i);
  }
  const auto unit = transfer(ch, lbp::Bytes{0x46, kUnitNumberAddress & 0xFF, kUnitNumberAddress >> 8}, 4, t);
  if (!unit) {
    out.cs = status_word(ch, Status::kNotReady | Status::kCommunicationError);
    return false;
  }
  ch.remote_mode = name == sslbp::kName8i20 ? sslbp::kRemoteMode8i20 : 0;
  if (mode == ChannelMode::Normal) {
    for (const lbp::Command& c : ch.remote->normal_start_commands()) {
      if (!transfer(ch, c.bytes, c.reply_bytes, t)) {
        out.cs = status_word(ch, Status::kNotReady | Status::kCommunicationError);
        return false;
      }
    }
    ch.remote->normal_started();
  }
  ch.mode = mode;
  ch.doit_seen = false;
  out.cs = status_word(ch, 0);
  out.interface0 = static_cast<std::uint32_t>(lbp::read_le(*unit));
  out.interface1 = name;
  return true;
}

bool SslbpEngine::doit(Channel& ch, Registers& out, Clock::time_point& t) {
  if (ch.mode == ChannelMode::Stopped || !ch.remote) {
    out.cs = status_word(ch, Status::kNotReady);
    return false;
  }
  if (ch.mode == ChannelMode::Setup) return passthrough(ch, out, t);
  // Normal mode: the cycle RPC, ANGLE (INTERFACE0 LSW) then QSETPOINT (MSW).
  lbp::Bytes command{lbp::rpc_command(kNormalCycleRpc)};
  lbp::append_le(command, ch.host.interface0, kNormalCycleStreamBytes);
  const auto reply = transfer(ch, command, kNormalCycleReplyBytes, t);
  ch.doit_seen = true;
  if (!reply) {
    out.cs = status_word(ch, Status::kCommunicationError);
    return false;
  }
  const lbp::ByteView r(*reply);
  // The RPC returns TEMPERATURE (0.01 C per count) and BUSV; INTERFACE0 presents "MSW = Bus
  // voltage in 10s of mV", "LSW = Card Temperature in oC" (8I20 manual, 8I20 SPECIFIC
  // INTERFACE REGISTER 0 DEFINITIONS): whole degrees, truncated (the manual does not say
  // how SSLBP rounds).
  const auto counts = static_cast<std::uint32_t>(lbp::read_le(r.subspan(0, 2)));
  const auto bus = static_cast<std::uint32_t>(lbp::read_le(r.subspan(2, 2)));
  out.interface0 = bus << 16 | (counts / 100);
  out.interface1 = static_cast<std::uint32_t>(lbp::read_le(r.subspan(4, 4)));
  const bool remote_fault = (out.interface1 >> 16) != 0;
  out.cs = status_word(ch, remote_fault ? Status::kRemoteFault : 0);
  return true;
}

bool SslbpEngine::passthrough(Channel& ch, Registers& out, Clock::time_point& t) {
  const auto header = static_cast<lbp::Byte>(ch.host.cs >> 24);
  lbp::Bytes command{header};
  std::size_t reply_bytes = 0;
  switch (lbp::kind_of(header)) {
    case lbp::CommandKind::Data: {
      const auto h = lbp::DataHeader::decode(header);
      if (!h.has_address || h.rpc_includes_data || h.size == lbp::DataSize::Eight) {
        out.cs = status_word(ch, Status::kCommunicationError);
        return false;
      }
      lbp::append_le(command, ch.host.cs & 0xFFFF, 2);
      if (h.write)
        lbp::append_le(command, ch.host.interface0, h.data_bytes());
      else
        reply_bytes = h.data_bytes();
      break;
    }
    case lbp::CommandKind::LocalRead: reply_bytes = 1; break;
    case lbp::CommandKind::LocalWrite:
      if (header == lbp::local::kResetParser) break;  // no data byte
      command.push_back(static_cast<lbp::Byte>(ch.host.interface0));
      break;
    default: out.cs = status_word(ch, Status::kCommunicationError); return false;
  }
  const auto reply = transfer(ch, command, reply_bytes, t);
  if (!reply) {
    out.cs = status_word(ch, Status::kCommunicationError);
    return false;
  }
  if (reply_bytes > 0) out.interface0 = static_cast<std::uint32_t>(lbp::read_le(*reply));
  out.cs = status_word(ch, 0);
  return true;
}

}  // namespace i20::ethsim
