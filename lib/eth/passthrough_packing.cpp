// SPDX-License-Identifier: GPL-2.0-or-later
// PassthroughPort's packing and replay: the rounds of each packet under the packing rules
// (passthrough_port.hpp), the NV access and RPC memory mode brackets around them, running
// a packet, and what follows a late DOIT or a lost reply. The port's lifecycle is in
// passthrough_port.cpp.
#include <algorithm>
#include <cassert>

#include "eth/errors.hpp"
#include "eth/passthrough_port.hpp"
#include "eth/passthrough_work.hpp"
#include "lbp/bytes.hpp"
#include "lbp/local.hpp"

namespace i20::eth {

using namespace passthrough_detail;  // lbp16, sslbp, microseconds, kFallbackBaud, bit, channels_of

namespace {

// What every packet starts with: UdpClient's sequence tag (write and read of space 6
// Scratch), FencedTransport's read of RXUDPCount and our own.
constexpr std::size_t kTagRequestBytes = 6 + 4 + 4 + 4;
constexpr std::size_t kTagReplyBytes = 2 + 2 + 2;

// A register's value from its reply bytes.
constexpr auto word = lbp::read_le32;

// Indexes into `channels` (ascending channel numbers) grouped into runs of neighbours, so
// that the registers of channels 2, 3, 4 move in one block access.
std::vector<std::vector<std::size_t>> runs_of(const std::vector<unsigned>& channels) {
  std::vector<std::vector<std::size_t>> runs;
  for (std::size_t i = 0; i < channels.size(); ++i) {
    if (runs.empty() || channels[runs.back().back()] + 1 != channels[i]) runs.emplace_back();
    runs.back().push_back(i);
  }
  return runs;
}

bool is_data_read(const PassthroughStep& step) {
  return step.effect == StepEffect::Read && step.data_bytes > 0;
}

// Rethrows `error` as the same kind of link error with another `completed` count.
std::exception_ptr with_completed(const std::exception_ptr& error, std::size_t completed) {
  try {
    std::rethrow_exception(error);
  } catch (const link::OutOfTime& e) {
    return std::make_exception_ptr(link::OutOfTime(e.what(), completed));
  } catch (const link::TimeoutError& e) {
    return std::make_exception_ptr(link::TimeoutError(e.what(), completed));
  } catch (const link::CrcError& e) {
    return std::make_exception_ptr(link::CrcError(e.what(), completed));
  } catch (const BadReplyError& e) {
    return std::make_exception_ptr(BadReplyError(e.what(), completed));
  } catch (const SslbpError& e) {
    return std::make_exception_ptr(SslbpError(e.what(), completed));
  } catch (const ForeignHostError& e) {
    return std::make_exception_ptr(ForeignHostError(e.what(), completed));
  } catch (const link::LinkError& e) {
    return std::make_exception_ptr(link::LinkError(e.what(), completed));
  } catch (...) {
    return std::current_exception();
  }
}

// The RPC memory access a step sets: 1 on, 0 off, -1 (not an 0xEA).
int rpc_mode_set_by(const PassthroughStep& step) {
  if ((step.cs >> 24) != lbp::local::kSetRpcMemAccess || !step.interface0) return -1;
  return *step.interface0 != 0 ? 1 : 0;
}

bool mode_on(const std::optional<std::uint8_t>& mode) {
  return mode.value_or(0) != 0;
}

}  // namespace

// ---- what a DOIT costs --------------------------------------------------------------------

std::chrono::microseconds PassthroughPort::serial_time(const PassthroughStep& step, unsigned channel) const {
  const std::uint64_t baud = bauds_.at(channel) ? bauds_.at(channel) : kFallbackBaud;
  const std::uint64_t characters = step.wire_bytes + options_.turnaround_characters;
  return microseconds(characters * 10 * 1'000'000 / baud);
}

std::chrono::microseconds PassthroughPort::settle_for(const PassthroughStep& step, unsigned channel,
                                                      std::optional<std::uint8_t> nv_mode) const {
  auto us = serial_time(step, channel) + options_.overhead + slack_;
  // A data write may be an EEPROM write: while NV access is on, or not known to be off.
  if (step.data_write && nv_mode.value_or(1) != 0)
    us += options_.nv_write_time * static_cast<long>(std::max<std::size_t>(1, step.data_bytes / 2));
  return us;
}

// A round that writes an EEPROM cell and reads nothing back: when it is late, the DOIT in
// flight is ours (nothing else can be), and DATA, once COMMAND clears, is its outcome
// (unless a later DOIT of the packet ran in the microsecond after our read-back; then the
// cell's failure could hide behind that DOIT's success, which the read-back of every NV
// write catches).
bool PassthroughPort::is_eeprom_write(const Round& round) {
  const bool writes = std::any_of(round.slots.begin(), round.slots.end(),
                                  [](const Slot& s) { return s.plan.data_write && s.mode.value_or(1) != 0; });
  const bool reads = std::any_of(round.slots.begin(), round.slots.end(),
                                 [](const Slot& s) { return s.plan.reply_bytes > 0; });
  return writes && !reads;
}

// A DOIT outlived its WaituS: the remote or SSLBP is slower than the estimate. Every later
// WaituS of this port gets longer (doubling, up to options.max_slack), so a slow card
// costs a few replays, not one per command. EEPROM writes do not teach: their time is a
// guess of its own (nv_write_time), and a slow cell only costs a poll.
void PassthroughPort::learn_from_late(const Round& round) {
  const bool eeprom = std::any_of(round.slots.begin(), round.slots.end(),
                                  [](const Slot& s) { return s.plan.data_write && s.mode.value_or(1) != 0; });
  if (eeprom) return;
  const microseconds step = std::max(round.settle - slack_, microseconds{50});
  slack_ = std::min(std::max(2 * slack_, step), microseconds(options_.max_slack));
}

// Fills in a round's mask, timing and LBP16 commands from its slots.
void PassthroughPort::lay_out(Round& round, const std::vector<Channel>& channels) const {
  const auto& regs = sslbp_->port().registers;
  std::vector<unsigned> numbers;
  round.mask = 0;
  round.settle = round.serial = microseconds{0};
  for (const Slot& s : round.slots) {
    const unsigned ch = channels[s.owner].channel;
    numbers.push_back(ch);
    round.mask |= bit(ch);
    round.settle = std::max(round.settle, settle_for(s.plan, ch, s.mode));
    round.serial = std::max(round.serial, serial_time(s.plan, ch));
  }
  round.commands.clear();
  round.interface0_reads.clear();
  // Registers of neighbouring channels are neighbours too (4 bytes apart): one block
  // access per run of channels.
  const auto write_run = [&](auto address_of, auto value_of, auto wanted) {
    std::vector<unsigned> chosen_channels;
    std::vector<std::size_t> chosen_slots;
    for (std::size_t i = 0; i < round.slots.size(); ++i)
      if (wanted(round.slots[i])) {
        chosen_channels.push_back(numbers[i]);
        chosen_slots.push_back(i);
      }
    for (const auto& run : runs_of(chosen_channels)) {
      std::vector<std::uint32_t> values;
      for (std::size_t k : run) values.push_back(value_of(round.slots[chosen_slots[k]]));
      round.commands.push_back(lbp16::write_hm2(address_of(chosen_channels[run.front()]), values));
    }
  };
  write_run([&](unsigned ch) { return regs.interface0(ch); },
            [](const Slot& s) { return *s.plan.interface0; },
            [](const Slot& s) { return s.plan.interface0.has_value(); });
  write_run([&](unsigned ch) { return regs.cs(ch); }, [](const Slot& s) { return s.plan.cs; },
            [](const Slot&) { return true; });
  round.commands.push_back(lbp16::write_hm2(regs.command, sslbp::doit(round.mask)));
  if (sslbp_->timer_space() && round.settle.count() > 0) {
    const auto us = static_cast<std::uint16_t>(std::min<std::int64_t>(round.settle.count(), 0xFFFF));
    round.commands.push_back(lbp16::write(lbp16::space::kTimers, kWaitMicrosecondsAddress,
                                          lbp16::Width::Bits16, lbp::to_le(us, 2), false));
  }
  round.command_read = round.commands.size();
  round.commands.push_back(lbp16::read_hm2(regs.command));
  round.commands.push_back(lbp16::read_hm2(regs.data));
  std::vector<unsigned> reading;
  std::vector<std::size_t> reading_slots;
  for (std::size_t i = 0; i < round.slots.size(); ++i)
    if (round.slots[i].plan.reply_bytes > 0) {
      reading.push_back(numbers[i]);
      reading_slots.push_back(i);
    }
  for (const auto& run : runs_of(reading)) {
    std::vector<std::size_t> served;
    for (std::size_t k : run) served.push_back(reading_slots[k]);
    round.interface0_reads.emplace_back(round.commands.size(), served);
    round.commands.push_back(
        lbp16::read_hm2(regs.interface0(reading[run.front()]), static_cast<unsigned>(run.size())));
  }
  round.request_bytes = round.reply_bytes = 0;
  for (const auto& c : round.commands) {
    round.request_bytes += c.request_bytes();
    round.reply_bytes += c.reply_bytes();
  }
}

// ---- executing batches --------------------------------------------------------------------

std::vector<ChannelResult> PassthroughPort::execute(std::span<const Batch> batches) {
  std::lock_guard lock(execute_mutex_);
  std::uint8_t seen = 0;
  for (const Batch& b : batches) {
    remote(b.channel);  // UsageError for a channel outside the mask
    if (seen & bit(b.channel))
      throw UsageError("two batches for channel " + std::to_string(b.channel) + " in one execute on " +
                       describe());
    seen |= bit(b.channel);
  }
  refuse_if_another_host_took_the_port();
  if (needs_resync_) resync();

  std::vector<Channel> work;
  for (const Batch& b : batches) {
    Channel c{.channel = b.channel, .commands = b.commands};
    for (std::size_t i = 0; i < b.commands.size(); ++i) {
      try {
        c.steps.push_back(plan_passthrough(b.commands[i]));
      } catch (const link::UnsupportedCommand& e) {
        c.unsupported = e.what();  // the commands before it still run, as on any link
        break;
      }
    }
    c.mode_before.push_back(nv_modes_[b.channel]);
    for (const PassthroughStep& step : c.steps)
      c.mode_before.push_back(step.nv_access_mode ? std::optional<std::uint8_t>(*step.nv_access_mode)
                                                  : c.mode_before.back());
    work.push_back(std::move(c));
  }
  const std::uint64_t trips_before = stats_.round_trips;
  run(work);
  stats_.max_round_trips = std::max(stats_.max_round_trips, stats_.round_trips - trips_before);

  std::vector<ChannelResult> outcomes;
  for (Channel& c : work) {
    ChannelResult o{.channel = c.channel};
    if (!c.error && c.unsupported)
      c.error = std::make_exception_ptr(link::UnsupportedCommand(*c.unsupported, c.steps.size()));
    if (c.error)
      o.error = c.error;
    else
      o.replies = std::move(c.replies);
    outcomes.push_back(std::move(o));
  }
  return outcomes;
}

void PassthroughPort::run(std::vector<Channel>& channels) {
  unsigned replays = 0, resends = 0;
  std::optional<Round> restore;
  bool slow = false;
  try {
    while (std::any_of(channels.begin(), channels.end(), [](const Channel& c) { return c.active(); })) {
      std::vector<Round> packet;
      if (restore) {
        packet.push_back(std::move(*restore));
        restore.reset();
      } else {
        // After a late DOIT its round goes alone: the poll then reads its own result.
        packet = next_packet(channels, slow ? 1u : options_.max_doits_per_packet, /*leave=*/!slow);
        bracket_modes(packet, channels, /*leave=*/!slow);
        slow = false;
      }
      PacketResult result = run_packet(packet, channels);
      restore = std::move(result.restore);
      slow = result.slow;
      if (result.next == PacketResult::Next::Replay && ++replays > options_.max_replays)
        throw link::TimeoutError(
            "SSLBP DOITs on " + describe() + " keep finishing later than their serial traffic needs (" +
            std::to_string(replays) + " replays in one exchange): the remote answers too slowly");
      // A packet whose reply was lost is resent within options_.lost_packet_resends; under
      // ops (0 resends) the caller's retry budget repeats the exchange instead.
      if (result.next == PacketResult::Next::Resend && ++resends > options_.lost_packet_resends)
        throw link::TimeoutError((resends == 1 ? "the reply from " + describe() + " was lost"
                                               : "the replies from " + describe() + " were lost " +
                                                     std::to_string(resends) + " times in a row") +
                                 "; the card or the network is not answering");
    }
  } catch (const link::LinkError&) {
    needs_resync_ = true;
    const auto error = std::current_exception();
    for (Channel& c : channels)
      if (c.active()) {
        c.failed = true;
        c.error = with_completed(error, c.next);
      }
  }
  describe_failures(channels);
}

// An 0xEA that turns RPC memory access off may follow other steps of its channel in a
// packet when the mode before it is known: on at the packet's start, or set by the
// channel's first step in it (an 0xEA opens the packet). Should a round before it be late
// and this one run in the race, the replay's bracket sets RPC memory access on again
// (rpc_modes_ holds the finished steps' mode), so the replayed reads still read the table.
// An 0xEA that turns it on must still open the packet: a round before it, replayed after
// it ran, would read the table where it meant working memory.
bool PassthroughPort::rpc_off_may_follow(const PassthroughStep& step, const Channel& c,
                                         std::size_t first_in_packet) const {
  if (rpc_mode_set_by(step) != 0) return false;
  return rpc_modes_[c.channel].has_value() || rpc_mode_set_by(c.steps[first_in_packet]) >= 0;
}

std::vector<PassthroughPort::Round> PassthroughPort::next_packet(std::vector<Channel>& channels,
                                                                 unsigned max_doits, bool leave) const {
  // What a channel already has in this packet: the packing rules (see the header) look
  // at it.
  struct Seen {
    bool any = false;
    bool data_read = false;
    std::size_t first = 0;
  };
  std::vector<Round> packet;
  std::vector<std::size_t> cursor;
  for (const Channel& c : channels) cursor.push_back(c.next);
  std::vector<Seen> seen(channels.size());
  std::size_t request = kTagRequestBytes, reply = kTagReplyBytes;
  microseconds wait{0};
  for (;;) {
    if (max_doits != 0 && packet.size() >= max_doits) break;
    Round round;
    bool allowed = true;
    for (std::size_t i = 0; i < channels.size(); ++i) {
      const Channel& c = channels[i];
      if (c.failed || cursor[i] >= c.steps.size()) continue;
      const PassthroughStep& step = c.steps[cursor[i]];
      const auto mode = c.mode_before[cursor[i]];
      round.slots.push_back(Slot{.owner = i, .step = cursor[i], .plan = step, .mode = mode});
      const Seen& s = seen[i];
      switch (step.effect) {
        case StepEffect::Read: break;
        case StepEffect::Unrepeatable: round.alone = true; break;
        case StepEffect::LocalWrite:
          allowed = allowed && (!s.any || rpc_off_may_follow(step, c, s.first));
          break;
        case StepEffect::NvMode:
          // Known where a replay needs it: at the packet's start, or set by the channel's
          // first step in it.
          allowed = allowed && (!s.any || c.mode_before[s.first].has_value() ||
                                c.steps[s.first].effect == StepEffect::NvMode);
          break;
        case StepEffect::DataWrite: allowed = allowed && !s.data_read; break;
      }
    }
    if (round.slots.empty()) break;
    if (round.alone) allowed = allowed && packet.empty();
    if (!sslbp_->timer_space()) round.ends_packet = true;  // nothing to wait with: poll each DOIT
    lay_out(round, channels);
    // The mode DOITs bracket_modes will add to the packet with this round in it.
    std::vector<const Round*> with_round;
    for (const Round& r : packet) with_round.push_back(&r);
    with_round.push_back(&round);
    std::size_t bracket_request = 0, bracket_reply = 0;
    microseconds bracket_wait{0};
    const auto [enter, leave_rounds] = mode_brackets(with_round, channels, leave);
    for (const auto* side : {&enter, &leave_rounds})
      for (const Round& r : *side) {
        bracket_request += r.request_bytes;
        bracket_reply += r.reply_bytes;
        bracket_wait += r.settle;
      }
    const bool fits = request + round.request_bytes + bracket_request <= lbp16::kMaxPayload &&
                      reply + round.reply_bytes + bracket_reply <= lbp16::kMaxPayload &&
                      wait + round.settle + bracket_wait <= options_.max_packet_wait;
    if (!packet.empty() && (!allowed || !fits)) break;
    for (const Slot& slot : round.slots) {
      Seen& s = seen[slot.owner];
      if (!s.any) s.first = *slot.step;
      s.any = true;
      s.data_read = s.data_read || is_data_read(slot.plan);
      ++cursor[slot.owner];
    }
    request += round.request_bytes;
    reply += round.reply_bytes;
    wait += round.settle;
    const bool last = round.alone || round.ends_packet;
    packet.push_back(std::move(round));
    if (last) break;
  }
  return packet;
}

// A copy of a packet that the network delivers late, or twice, runs again on its own,
// whenever it arrives. So no packet relies on, or leaves, an 8I20 in NV access or RPC
// memory mode: a channel whose commands in the packet run in such a mode gets it set by
// the packet's first DOITs and cleared by its last. Between packets every 8I20 is in
// normal access, whatever the tool's commands asked for (nv_modes_, rpc_modes_ and
// mode_before keep that). A late or repeated copy then writes the EEPROM cell it was meant
// for, not working memory at the EEPROM address, reads the RPC table it was meant to, and
// cannot leave a mode on after the tool's last packet. `leave` false: no last DOITs (a
// packet whose one round follows a late DOIT polls for its own result, so nothing may
// follow that round).
void PassthroughPort::bracket_modes(std::vector<Round>& packet, const std::vector<Channel>& channels,
                                    bool leave) const {
  std::vector<const Round*> rounds;
  for (const Round& r : packet) rounds.push_back(&r);
  auto [before, after] = mode_brackets(rounds, channels, leave);
  packet.insert(packet.begin(), std::make_move_iterator(before.begin()),
                std::make_move_iterator(before.end()));
  packet.insert(packet.end(), std::make_move_iterator(after.begin()), std::make_move_iterator(after.end()));
}

// The rounds that bracket_modes puts before and after `packet`, laid out.
std::pair<std::vector<PassthroughPort::Round>, std::vector<PassthroughPort::Round>>
PassthroughPort::mode_brackets(const std::vector<const Round*>& packet, const std::vector<Channel>& channels,
                               bool leave) const {
  if (packet.empty() || !sslbp_->timer_space()) return {};
  Round enter_nv, enter_rpc, leave_rpc, leave_nv;
  const auto add = [&](Round& round, std::size_t owner, lbp::Byte command, std::uint8_t value,
                       std::optional<std::uint8_t> nv) {
    round.slots.push_back(Slot{.owner = owner,
                               .step = std::nullopt,
                               .plan = plan_passthrough(lbp::local_write(command, value)),
                               .mode = nv});
  };
  for (std::size_t owner = 0; owner < channels.size(); ++owner) {
    std::vector<const Slot*> mine;
    for (const Round* r : packet)
      for (const Slot& slot : r->slots)
        if (slot.owner == owner) mine.push_back(&slot);
    if (mine.empty()) continue;
    const Slot& first = *mine.front();
    const Slot& last = *mine.back();
    // NV access: the mode each slot runs in is known from the channel's plan.
    if (mode_on(first.mode) && first.plan.effect != StepEffect::NvMode)
      add(enter_nv, owner, lbp::local::kSetNvAccess, *first.mode, first.mode);
    std::optional<std::uint8_t> nv_after = last.mode;
    if (last.plan.nv_access_mode) nv_after = *last.plan.nv_access_mode;
    if (last.plan.effect == StepEffect::Unrepeatable) nv_after.reset();  // a reset leaves the modes
    if (leave && mode_on(nv_after)) add(leave_nv, owner, lbp::local::kSetNvAccess, 0, std::uint8_t{0});
    // RPC memory access: from the mode the finished commands left, through this packet's.
    const unsigned ch = channels[owner].channel;
    int rpc = rpc_modes_[ch] ? *rpc_modes_[ch] : -1;  // -1: not known
    if (rpc == 1 && rpc_mode_set_by(first.plan) < 0)
      add(enter_rpc, owner, lbp::local::kSetRpcMemAccess, 1, first.mode);
    for (const Slot* slot : mine) {
      if (const int set = rpc_mode_set_by(slot->plan); set >= 0) rpc = set;
      if (slot->plan.effect == StepEffect::Unrepeatable) rpc = -1;
    }
    if (leave && rpc == 1) add(leave_rpc, owner, lbp::local::kSetRpcMemAccess, 0, nv_after);
  }
  std::vector<Round> before, after;
  for (Round* r : {&enter_nv, &enter_rpc})
    if (!r->slots.empty()) before.push_back(std::move(*r));
  for (Round* r : {&leave_rpc, &leave_nv})
    if (!r->slots.empty()) after.push_back(std::move(*r));
  for (Round& r : before) lay_out(r, channels);
  for (Round& r : after) lay_out(r, channels);
  return {std::move(before), std::move(after)};
}

PassthroughPort::PacketResult PassthroughPort::run_packet(std::vector<Round>& packet,
                                                          std::vector<Channel>& channels) {
  // First RXUDPCount: whether anyone else's packets reached the card since our last one.
  std::vector<lbp16::Command> commands{received_count_read()};
  std::vector<std::size_t> offsets;
  for (const Round& r : packet) {
    offsets.push_back(commands.size());
    commands.insert(commands.end(), r.commands.begin(), r.commands.end());
  }
  std::vector<lbp::Bytes> parts;
  std::uint64_t sent = 0;
  ++stats_.round_trips;
  try {
    // Never resent blindly: it holds writes. A lost reply is sorted out by lost_reply().
    parts = bus_->transact_counted(commands, Resend::Never, sent);
  } catch (const link::TimeoutError&) {
    return lost_reply(packet, channels);
  }
  require_no_foreign_packets(static_cast<std::uint16_t>(lbp::read_le(parts.front())), sent);
  for (std::size_t r = 0; r < packet.size(); ++r) {
    Round& round = packet[r];
    const std::size_t at = offsets[r] + round.command_read;
    ++stats_.doits;
    stats_.serial_time += round.serial;
    if ((word(parts[at]) & 0xFFFF) != 0) {
      ++stats_.late_doits;
      learn_from_late(round);
      // From here on the round's result is read in later packets: it is ours only if no
      // other packet ran in between (the transport's ledger sees every arrival).
      const std::uint64_t foreign_before = bus_->stats().foreign_arrivals;
      if (r + 1 == packet.size()) {
        // Nothing was issued after it: wait for it, what the polls read is its result.
        const Completion done = sslbp_->poll(interface0_addresses(round, channels), sslbp::doit(round.mask));
        require_undisturbed(foreign_before);
        complete_by_polling(round, channels, done);
        return {};
      }
      if (is_eeprom_write(round)) {
        // An EEPROM cell that took longer than its WaituS: wait for it and take DATA as its
        // outcome rather than write the cell again; the rest of the packet replays.
        const Completion idle = sslbp_->poll({}, sslbp::doit(round.mask));
        require_undisturbed(foreign_before);
        stats_.round_trips += idle.round_trips;
        ++stats_.replays;
        for (const Slot& slot : round.slots) finish(channels, slot, 0, idle.data);
        return {PacketResult::Next::Replay, restore_round(packet, r + 1, channels)};
      }
      // SSLBP ignored the next DOITs of this packet, or (a microsecond race) ran one: wait
      // until it is idle, restore the NV mode the late round expects, replay from it.
      // A channel whose DATA bit is set failed there (or just after): it ends, the others
      // replay. Later WaituS get longer.
      const Completion idle = sslbp_->poll({}, sslbp::doit(round.mask));
      require_undisturbed(foreign_before);
      stats_.round_trips += idle.round_trips;
      ++stats_.replays;
      for (const Slot& slot : round.slots)
        if (slot.step && (idle.data & bit(channels[slot.owner].channel)))
          finish(channels, slot, 0, idle.data);
      return {PacketResult::Next::Replay, restore_round(packet, r, channels), /*slow=*/true};
    }
    const auto data = static_cast<std::uint8_t>(word(parts[at + 1]));
    std::vector<std::uint32_t> interface0(round.slots.size(), 0);
    for (const auto& [index, served] : round.interface0_reads) {
      const auto words = lbp16::words32(parts[offsets[r] + index]);
      for (std::size_t k = 0; k < served.size(); ++k) interface0[served[k]] = words.at(k);
    }
    for (std::size_t i = 0; i < round.slots.size(); ++i)
      finish(channels, round.slots[i], interface0[i], data);
  }
  return {};
}

PassthroughPort::PacketResult PassthroughPort::lost_reply(std::vector<Round>& packet,
                                                          std::vector<Channel>& channels) {
  // The reply is lost, the packet maybe too, or only late. First the fence: until the card's
  // count shows the packet arrived (or the bound passed), nothing else is sent, so a late
  // copy cannot run after what follows. Then a read-only probe reads what it left.
  const std::uint64_t foreign_before = bus_->stats().foreign_arrivals;
  const FenceReport fence = bus_->fence();
  const Round& last = packet.back();
  const Completion probe = sslbp_->poll(interface0_addresses(last, channels), sslbp::doit(last.mask));
  require_undisturbed(foreign_before);
  // Without a ledger (a transport that cannot fence) a DOIT still running is the evidence.
  const bool arrived = fence.needed ? fence.all_arrived : probe.round_trips > 1;
  if (packet.size() == 1 && arrived) {
    // Its only DOIT ran and only read-only probes followed: these are its results.
    complete_by_polling(packet.front(), channels, probe);
    return {};
  }
  stats_.round_trips += probe.round_trips;
  if (packet.front().alone)
    throw link::TimeoutError(
        "the reply from " + describe() + " was lost and the command cannot be resent safely: " +
        (fence.needed ? "the card had not received it " + std::to_string(fence.waited.count()) +
                            " ms later, so it most likely did not take effect"
                      : std::string("it may or may not have taken effect")));
  ++stats_.replays;
  return {PacketResult::Next::Resend, restore_round(packet, 0, channels)};
}

std::vector<std::uint16_t> PassthroughPort::interface0_addresses(const Round& round,
                                                                 const std::vector<Channel>& channels) const {
  std::vector<std::uint16_t> out;
  for (const Slot& s : round.slots)
    if (s.plan.reply_bytes > 0) out.push_back(sslbp_->port().registers.interface0(channels[s.owner].channel));
  return out;
}

void PassthroughPort::complete_by_polling(const Round& round, std::vector<Channel>& channels,
                                          const Completion& done) {
  stats_.round_trips += done.round_trips;
  std::vector<std::uint32_t> interface0(round.slots.size(), 0);
  std::size_t next = 0;
  for (std::size_t i = 0; i < round.slots.size(); ++i)
    if (round.slots[i].plan.reply_bytes > 0) interface0[i] = done.results.at(next++);
  for (std::size_t i = 0; i < round.slots.size(); ++i)
    finish(channels, round.slots[i], interface0[i], done.data);
}

std::optional<PassthroughPort::Round> PassthroughPort::restore_round(const std::vector<Round>& packet,
                                                                     std::size_t late,
                                                                     std::vector<Channel>& channels) const {
  Round restore;
  restore.alone = true;
  for (const Slot& s : packet[late].slots) {
    Channel& c = channels[s.owner];
    if (c.failed || s.plan.effect == StepEffect::NvMode) continue;  // replaying an 0xEC sets the mode itself
    bool changed_later = false;
    for (std::size_t r = late + 1; r < packet.size(); ++r)
      for (const Slot& t : packet[r].slots)
        changed_later = changed_later || (t.owner == s.owner && t.plan.effect == StepEffect::NvMode);
    if (!changed_later) continue;
    if (!s.mode) {  // the packing rules keep this from happening
      c.failed = true;
      c.error = std::make_exception_ptr(SslbpError(
          "the NV access mode of the 8I20 on " + describe(c.channel) +
              " is not known after a late DOIT: run the command again (i20 reset if it stays in NV mode)",
          c.next));
      continue;
    }
    const lbp::Command command = lbp::local_write(lbp::local::kSetNvAccess, *s.mode);
    restore.slots.push_back(
        Slot{.owner = s.owner, .step = std::nullopt, .plan = plan_passthrough(command), .mode = s.mode});
  }
  if (restore.slots.empty()) return std::nullopt;
  lay_out(restore, channels);
  return restore;
}

void PassthroughPort::finish(std::vector<Channel>& channels, const Slot& slot, std::uint32_t interface0,
                             std::uint8_t data) {
  Channel& c = channels[slot.owner];
  if (c.failed) return;  // its later DOITs in the packet ran, but its batch already ended
  const bool failed = (data & bit(c.channel)) != 0;
  if (!slot.step) {  // a mode DOIT of the port's own: a restore before a replay, or a bracket
    if (failed) {
      c.failed = true;
      c.error = std::make_exception_ptr(
          SslbpError("could not set the NV access or RPC memory mode of the 8I20 on " + describe(c.channel) +
                         " around its commands; the mode is unknown: reset it (i20 reset)",
                     c.next));
      needs_resync_ = true;
    }
    return;
  }
  assert(*slot.step == c.next);
  if (failed) {
    c.failed = true;
    c.failed_transfer = c.next;
    nv_modes_[c.channel].reset();  // whatever it was doing, we no longer know
    rpc_modes_[c.channel].reset();
    needs_resync_ = true;
    return;
  }
  c.replies.push_back(reply_from_interface0(interface0, slot.plan.reply_bytes));
  ++c.next;
  ++stats_.commands;
  learn_modes(c.channel, slot.plan, interface0);
  if (slot.plan.nv_access_mode) nv_modes_[c.channel] = *slot.plan.nv_access_mode;
  if (const int rpc = rpc_mode_set_by(slot.plan); rpc >= 0)
    rpc_modes_[c.channel] = static_cast<std::uint8_t>(rpc);
  if (slot.plan.effect == StepEffect::Unrepeatable) {  // a reset leaves NV and RPC memory mode
    nv_modes_[c.channel].reset();
    rpc_modes_[c.channel].reset();
  }
}

// A read of the NV access mode (0xCC) or of RPC memory access (0xCA) while the mode is not
// known (no packet bracket set it, so the read saw the card as it was): its answer is the
// mode. The device layer's first batch reads both (Amp8i20::info), so the opening needs
// no DOIT of its own for them.
void PassthroughPort::learn_modes(unsigned channel, const PassthroughStep& step, std::uint32_t interface0) {
  if (step.data_write || step.interface0 || step.reply_bytes != 1) return;
  const auto value = static_cast<std::uint8_t>(interface0 & 0xFF);
  const auto command = static_cast<lbp::Byte>(step.cs >> 24);
  if (command == lbp::local::kGetNvAccess && !nv_modes_[channel]) nv_modes_[channel] = value;
  if (command == lbp::local::kGetRpcMemAccess && !rpc_modes_[channel])
    rpc_modes_[channel] = static_cast<std::uint8_t>(value != 0 ? 1 : 0);
}

void PassthroughPort::describe_failures(std::vector<Channel>& channels) {
  std::uint8_t mask = 0;
  for (const Channel& c : channels)
    if (c.failed_transfer) mask |= bit(c.channel);
  if (mask == 0) return;
  std::vector<ChannelRegisters> regs;
  try {
    ++stats_.round_trips;
    regs = sslbp_->read_channels(mask);
  } catch (const link::LinkError&) {
    // The failure is the news; without CS it is reported in fewer words.
  }
  for (Channel& c : channels) {
    if (!c.failed_transfer) continue;
    const std::size_t step = *c.failed_transfer;
    const auto channels_before = channels_of(static_cast<std::uint8_t>(mask & (bit(c.channel) - 1))).size();
    std::string message = "the remote on " + describe(c.channel) + " did not complete LBP command " +
                          lbp::to_hex(c.commands[step].bytes);
    if (regs.empty()) {
      c.error =
          std::make_exception_ptr(SslbpError(message + " (SSLBP flagged the transfer; CS unreadable)", step));
      continue;
    }
    const std::uint32_t cs = regs[channels_before].cs;
    const sslbp::ChannelStatus status{cs};
    message += " (SSLBP CS " + lbp::hex_value(cs, 8) + ": " + status.describe() + ")";
    if (status.not_ready()) port_left_setup_ = needs_resync_ = true;
    if (status.timed_out())
      c.error = std::make_exception_ptr(link::TimeoutError(message, step));
    else if (status.crc_error())
      c.error = std::make_exception_ptr(link::CrcError(message, step));
    else
      c.error = std::make_exception_ptr(SslbpError(message, step));
  }
}

}  // namespace i20::eth
