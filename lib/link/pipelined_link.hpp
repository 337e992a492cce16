// SPDX-License-Identifier: GPL-2.0-or-later
// Setup-mode LBP over a byte stream (manual, "FRAMING"): the 8I20 frames commands by
// pre-parsing, so a batch can go out back to back and the replies are cut apart by
// their expected lengths. Two cautions bound the pipelining (docs/facts.md section 7): the
// card's receive buffer size is unpublished, so the bytes of unanswered commands are
// capped by a window; and barrier commands (EEPROM writes, resets) must be answered
// before anything else is sent.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "link/byte_stream.hpp"
#include "link/given.hpp"
#include "link/link.hpp"

namespace i20::link {

struct PipelinedLinkOptions {
  // Reply timeout per wait = base_timeout + wire time of the bytes in flight. 50 ms
  // covers a USB adapter's latency timer (16 ms on FTDI unless lowered) with margin.
  Given<std::chrono::milliseconds> base_timeout;
  // Wire bytes (CRC included) of commands sent but not yet answered. A single command
  // larger than the window is still sent, alone.
  std::size_t window_bytes = 64;
  // How often a failed batch is resent. Only batches that cannot change the card's
  // state are ever retried (see PipelinedLink::retry_safe); writes never are.
  Given<unsigned> retries;
  // Quiet time that resynchronises the card's parser after an error. Zero: twice the
  // longest command timeout (25.5 character times) at the stream's baud, plus 2 ms.
  std::chrono::microseconds resync_idle{0};
  // A card that keeps talking while we wait for quiet is not going to stop: how long past
  // the quiet time draining goes on before the next batch is left to report what it sees.
  Given<std::chrono::milliseconds> max_drain;
};

struct LinkStatistics {
  std::uint64_t exchanges = 0;       // execute() calls with at least one command
  std::uint64_t commands = 0;        // commands answered with a valid reply
  std::uint64_t bursts = 0;          // stream write() calls
  std::uint64_t bytes_sent = 0;      // wire bytes, CRCs included
  std::uint64_t bytes_received = 0;  // wire bytes, stale ones included
  std::uint64_t timeouts = 0;
  std::uint64_t crc_errors = 0;
  std::uint64_t framing_errors = 0;
  std::uint64_t resyncs = 0;
  std::uint64_t retries = 0;
  std::uint64_t stale_bytes = 0;        // received outside any batch's replies and dropped
  std::size_t max_bytes_in_flight = 0;  // highest command bytes awaiting replies
};

// Not thread-safe: one caller at a time (the 8I20 is a single master-slave line anyway).
class PipelinedLink final : public Link {
 public:
  using Options = PipelinedLinkOptions;

  PipelinedLink(std::unique_ptr<ByteStream> stream, Options options);

  std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) override;
  std::string describe() const override { return stream_->name(); }
  std::vector<std::string> notes() const override { return stream_->notes(); }

  const LinkStatistics& statistics() const { return stats_; }
  void reset_statistics() { stats_ = {}; }
  const Options& options() const { return options_; }
  const ByteStream& stream() const { return *stream_; }

  // True when resending the batch cannot change the card's state or its answers: only
  // reads, and reads at the address pointer only after the batch has set the pointer
  // itself (or when nothing in the batch moves the pointer).
  static bool retry_safe(std::span<const lbp::Command> batch);

  // The quiet time used to resynchronise, after defaults are applied.
  std::chrono::microseconds resync_idle() const;

 private:
  struct Run;

  std::vector<lbp::Bytes> run_once(std::span<const lbp::Command> batch);
  void drop_stale_input();
  void send_burst(Run& run);
  void await_reply(Run& run);
  void accept_replies(Run& run);
  [[noreturn]] void fail_timeout(const Run& run, std::chrono::microseconds waited);
  bool echoes(const Run& run) const;
  [[noreturn]] void fail_echo(const Run& run);
  void resynchronise();
  std::chrono::microseconds wire_time(std::size_t bytes) const;

  std::unique_ptr<ByteStream> stream_;
  Options options_;
  LinkStatistics stats_;
  // When the last byte we wrote has surely left the wire: the card's command timeout
  // only starts counting after it.
  Clock::time_point tx_quiet_from_{};
};

}  // namespace i20::link
