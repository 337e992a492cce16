// SPDX-License-Identifier: GPL-2.0-or-later
#include "link/pipelined_link.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "lbp/header.hpp"
#include "lbp/local.hpp"
#include "lbp/preparse.hpp"
#include "link/ports.hpp"
#include "link/wait_bound.hpp"

namespace i20::link {
namespace {

using lbp::Byte;
using lbp::Bytes;
using lbp::Command;

// The longest command timeout the 8I20 knows: 0xCB counts character times / 10 in a
// byte, and setup mode uses the maximum (manual, "FRAMING": 25.5 character times).
constexpr double kMaxCommandTimeoutChars = 25.5;
constexpr unsigned kBitsPerChar = 10;  // 8N1: start + 8 data + stop

std::size_t wire_size(const Command& c) {
  return c.bytes.size() + 1;
}

std::string hex_byte(unsigned value) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", value & 0xFFu);
  return text;
}

// "read 2 bytes at 0x0874 [45 74 08]": what the command is, in words and bytes.
std::string describe_command(const Command& c) {
  const std::string bytes = "[" + lbp::to_hex(c.bytes) + "]";
  const Byte header = c.bytes.front();
  switch (lbp::kind_of(header)) {
    case lbp::CommandKind::Data: {
      const auto h = lbp::DataHeader::decode(header);
      std::string where = "at the address pointer";
      if (h.has_address && c.bytes.size() >= 3) {
        char address[8];
        std::snprintf(address, sizeof address, "0x%04X",
                      unsigned(lbp::read_le(lbp::ByteView(c.bytes).subspan(1, 2))));
        where = std::string("at ") + address;
      }
      const auto n = h.data_bytes();
      return std::string(h.write ? "write " : "read ") + std::to_string(n) + (n == 1 ? " byte " : " bytes ") +
             where + " " + bytes;
    }
    case lbp::CommandKind::LocalRead:
    case lbp::CommandKind::LocalWrite: {
      const auto name = lbp::local::name_of(header);
      return (name ? std::string(*name) : "local command " + hex_byte(header)) + " " + bytes;
    }
    case lbp::CommandKind::Rpc: return "RPC " + std::to_string(header & 0x3F) + " " + bytes;
    default: return "command " + bytes;
  }
}

std::string position(std::size_t index, std::size_t count) {
  return "command " + std::to_string(index + 1) + " of " + std::to_string(count);
}

std::string milliseconds_text(std::chrono::microseconds t) {
  return std::to_string((t.count() + 999) / 1000) + " ms";
}

void validate(const PipelinedLinkOptions& options) {
  if (options.window_bytes == 0) throw UsageError("the pipelining window must allow at least one byte");
  if (options.base_timeout.count() <= 0) throw UsageError("the base reply timeout must be positive");
  if (options.resync_idle.count() < 0) throw UsageError("the resync idle time cannot be negative");
}

void validate(std::span<const Command> batch) {
  for (std::size_t i = 0; i < batch.size(); ++i)
    if (batch[i].bytes.empty()) throw UsageError(position(i, batch.size()) + " has no bytes to send");
}

std::vector<std::size_t> reply_sizes(std::span<const Command> batch) {
  std::vector<std::size_t> sizes;
  sizes.reserve(batch.size());
  for (const auto& c : batch) sizes.push_back(c.reply_bytes);
  return sizes;
}

// Re-raises a stream failure with the number of replies validated so far, keeping its type.
[[noreturn]] void rethrow_with_completed(const LinkError& e, std::size_t completed) {
  if (dynamic_cast<const TimeoutError*>(&e)) throw TimeoutError(e.what(), completed);
  throw LinkError(e.what(), completed);
}

}  // namespace

// State of one attempt at one batch.
namespace {
constexpr std::size_t kEchoWindow = 64;  // bytes compared for an echo
}  // namespace

struct PipelinedLink::Run {
  std::span<const Command> batch;
  lbp::ReplySplitter splitter;
  std::vector<Bytes> replies;
  std::size_t sent = 0;           // commands written
  std::size_t command_bytes = 0;  // wire bytes of written, unanswered commands
  std::size_t reply_bytes = 0;    // wire bytes of their replies still to come
  std::size_t received = 0;       // wire bytes read during this run
  bool barrier_pending = false;   // a barrier is written and not answered yet
  // The first bytes written and read, to tell a port that echoes what it is sent (a
  // loopback plug, TX wired to RX) from a card: an echo is no reply.
  Bytes written, read;

  explicit Run(std::span<const Command> b) : batch(b), splitter(reply_sizes(b)) { replies.reserve(b.size()); }
  bool done() const { return replies.size() == batch.size(); }
};

PipelinedLink::PipelinedLink(std::unique_ptr<ByteStream> stream, Options options)
    : stream_(std::move(stream)), options_(options) {
  if (!stream_) throw UsageError("PipelinedLink needs a byte stream");
  validate(options_);
}

std::chrono::microseconds PipelinedLink::wire_time(std::size_t bytes) const {
  const auto baud = std::max(stream_->baud(), 1u);
  const auto bits = static_cast<std::uint64_t>(bytes) * kBitsPerChar;
  return std::chrono::microseconds((bits * 1'000'000 + baud - 1) / baud);
}

std::chrono::microseconds PipelinedLink::resync_idle() const {
  if (options_.resync_idle.count() > 0) return options_.resync_idle;
  // Twice the card's longest command timeout, plus slack for USB adapter scheduling.
  const auto baud = std::max(stream_->baud(), 1u);
  const double seconds = 2 * kMaxCommandTimeoutChars * kBitsPerChar / baud;
  return std::chrono::microseconds(static_cast<std::int64_t>(seconds * 1e6) + 2000);
}

bool PipelinedLink::retry_safe(std::span<const Command> batch) {
  bool pointer_set = false;  // an addressed read has put the pointer somewhere known
  bool moves_pointer = false;
  bool reads_at_pointer_unset = false;
  for (const auto& c : batch) {
    if (c.bytes.empty()) return false;
    const Byte header = c.bytes.front();
    const auto kind = lbp::kind_of(header);
    if (kind == lbp::CommandKind::LocalRead) continue;
    if (kind != lbp::CommandKind::Data) return false;  // local writes, RPCs (may write), junk
    const auto h = lbp::DataHeader::decode(header);
    if (h.write) return false;
    moves_pointer = moves_pointer || h.auto_increment;
    if (h.has_address)
      pointer_set = true;
    else if (!pointer_set)
      reads_at_pointer_unset = true;
  }
  // A read at an unset pointer gives the same answer again only if nothing moved it.
  return !(reads_at_pointer_unset && moves_pointer);
}

std::vector<Bytes> PipelinedLink::execute(std::span<const Command> batch) {
  validate(batch);
  if (batch.empty()) return {};
  ++stats_.exchanges;
  const bool may_retry = options_.retries > 0 && retry_safe(batch);
  for (unsigned attempt = 0;; ++attempt) {
    try {
      return run_once(batch);
    } catch (const LinkError& e) {
      const bool transient = dynamic_cast<const TimeoutError*>(&e) || dynamic_cast<const CrcError*>(&e) ||
                             dynamic_cast<const FramingError*>(&e);
      if (!transient || !may_retry || attempt >= options_.retries) throw;
      ++stats_.retries;  // run_once has resynchronised already
    }
  }
}

std::vector<Bytes> PipelinedLink::run_once(std::span<const Command> batch) {
  drop_stale_input();
  Run run(batch);
  while (!run.done()) {
    try {
      if (!run.barrier_pending) send_burst(run);
      await_reply(run);
    } catch (const TimeoutError&) {
      throw;
    } catch (const CrcError&) {
      throw;
    } catch (const FramingError&) {
      throw;
    } catch (const LinkError& e) {
      rethrow_with_completed(e, run.replies.size());  // the stream itself failed
    }
  }
  if (const auto surplus = run.splitter.surplus_bytes(); surplus > 0) {
    ++stats_.framing_errors;
    resynchronise();
    throw FramingError("the 8I20 on " + stream_->name() + " sent " + std::to_string(surplus) +
                           " byte(s) more than the replies to this batch; reply framing was lost, so none "
                           "of them can be trusted (resynchronised; read back before relying on writes)",
                       0);
  }
  stats_.commands += run.replies.size();
  return std::move(run.replies);
}

// Bytes waiting before we sent anything belong to no command of ours: a late reply to
// a batch that failed, or noise. Left in place they would shift every reply.
void PipelinedLink::drop_stale_input() {
  std::array<Byte, 256> buffer;
  const auto n = stream_->read_some(buffer, Clock::now());
  if (n == 0) return;
  stats_.bytes_received += n;
  stats_.stale_bytes += n;
  resynchronise();
}

void PipelinedLink::send_burst(Run& run) {
  Bytes burst;
  while (run.sent < run.batch.size()) {
    const Command& c = run.batch[run.sent];
    const auto size = wire_size(c);
    if (run.command_bytes > 0 && run.command_bytes + size > options_.window_bytes) break;
    const auto framed = lbp::frame(c);
    burst.insert(burst.end(), framed.begin(), framed.end());
    run.command_bytes += size;
    run.reply_bytes += c.reply_bytes + 1;
    ++run.sent;
    if (c.barrier) {
      run.barrier_pending = true;  // nothing more until it is answered
      break;
    }
  }
  if (burst.empty()) return;
  if (run.written.size() < kEchoWindow) run.written.insert(run.written.end(), burst.begin(), burst.end());
  stream_->write(burst);
  tx_quiet_from_ = Clock::now() + wire_time(burst.size());
  ++stats_.bursts;
  stats_.bytes_sent += burst.size();
  stats_.max_bytes_in_flight = std::max(stats_.max_bytes_in_flight, run.command_bytes);
}

// Waits until at least one more reply is complete and accepted.
void PipelinedLink::await_reply(Run& run) {
  const auto before = run.replies.size();
  const auto full = std::chrono::duration_cast<std::chrono::microseconds>(options_.base_timeout) +
                    wire_time(run.command_bytes + run.reply_bytes);
  // The operation's end cuts the wait short (WaitBound): past it, only the way back runs.
  const auto timeout = std::chrono::duration_cast<std::chrono::microseconds>(WaitBound::cap(full));
  const auto deadline = Clock::now() + timeout;
  std::array<Byte, 256> buffer;
  for (;;) {
    accept_replies(run);
    if (run.replies.size() > before) return;
    const auto n = stream_->read_some(buffer, deadline);
    if (n == 0) fail_timeout(run, timeout);
    run.splitter.push(lbp::ByteView(buffer.data(), n));
    if (run.read.size() < kEchoWindow) run.read.insert(run.read.end(), buffer.begin(), buffer.begin() + n);
    run.received += n;
    stats_.bytes_received += n;
  }
}

// Every byte read so far is the start of what was written: the port echoes.
bool PipelinedLink::echoes(const Run& run) const {
  const auto n = std::min(run.read.size(), run.written.size());
  return n >= 2 &&
         std::equal(run.read.begin(), run.read.begin() + static_cast<std::ptrdiff_t>(n), run.written.begin());
}

[[noreturn]] void PipelinedLink::fail_echo(const Run& run) {
  resynchronise();
  throw TimeoutError("the port " + stream_->name() + " sends back exactly what the tool writes (" +
                         std::to_string(std::min(run.read.size(), run.written.size())) +
                         " bytes): a loopback plug, or TX wired to RX; no 8I20 answered. Is the cable on the "
                         "8I20's J1, and wired TX to RX and RX to TX?",
                     0);
}

void PipelinedLink::accept_replies(Run& run) {
  while (auto reply = run.splitter.next()) {
    const auto index = run.replies.size();
    const Command& c = run.batch[index];
    if (!reply->crc_ok && index == 0 && echoes(run)) fail_echo(run);
    if (!reply->crc_ok) {
      ++stats_.crc_errors;
      resynchronise();
      throw CrcError("reply to " + position(index, run.batch.size()) + " (" + describe_command(c) +
                         ") from the 8I20 on " + stream_->name() + " has a bad CRC: got [" +
                         lbp::to_hex(reply->data) + "] with CRC " + hex_byte(reply->received_crc) +
                         ", expected " + hex_byte(reply->expected_crc) +
                         "; check the cable and termination (W4/W5), and W6 down for setup mode",
                     index);
    }
    run.replies.push_back(std::move(reply->data));
    run.command_bytes -= wire_size(c);
    run.reply_bytes -= c.reply_bytes + 1;
    if (c.barrier) run.barrier_pending = false;
  }
}

void PipelinedLink::fail_timeout(const Run& run, std::chrono::microseconds waited) {
  ++stats_.timeouts;
  resynchronise();
  const auto completed = run.replies.size();
  const auto& port = stream_->name();
  if (completed == 0 && echoes(run)) fail_echo(run);
  if (run.received == 0 && completed == 0) {
    // A second program reading the port takes the replies: name it before blaming the wiring.
    const auto others = other_programs_with(port);
    if (!others.empty())
      throw TimeoutError("no reply from the 8I20 on " + port + " within " + milliseconds_text(waited) + ": " +
                             others.front() + (others.size() > 1 ? " and others" : "") +
                             " also has the port open and may be reading the card's replies; end it first",
                         0);
    throw TimeoutError("no reply from the 8I20 on " + port + " within " + milliseconds_text(waited) +
                           ": is jumper W6 down (setup mode), is logic power on, is the cable in J1?",
                       0);
  }
  throw TimeoutError("the 8I20 on " + port + " answered " + std::to_string(completed) + " of " +
                         std::to_string(run.batch.size()) + " commands, then nothing for " +
                         milliseconds_text(waited) + " (waiting for the reply to " +
                         position(completed, run.batch.size()) + ", " +
                         describe_command(run.batch[completed]) +
                         "): it may have dropped a corrupted command or overflowed its receive buffer; "
                         "try a smaller window",
                     completed);
}

// Manual, "FRAMING": timing still frames aborted packets, so a quiet line longer than
// the card's command timeout resets its parser. Meanwhile whatever it still sends
// (replies to the rest of a failed batch) is read and dropped, then the OS buffer too.
void PipelinedLink::resynchronise() {
  ++stats_.resyncs;
  const auto idle = resync_idle();
  const auto now = Clock::now();
  const auto give_up = now + idle + options_.max_drain.get();
  auto quiet_until = std::max(now, tx_quiet_from_) + idle;
  std::array<Byte, 256> buffer;
  for (;;) {
    const auto n = stream_->read_some(buffer, std::min(quiet_until, give_up));
    if (n == 0) break;
    stats_.bytes_received += n;
    stats_.stale_bytes += n;
    quiet_until = Clock::now() + idle;
  }
  stream_->discard_input();
}

}  // namespace i20::link
