// SPDX-License-Identifier: GPL-2.0-or-later
// The retry budget: how often one logical exchange with a card (a read, a read-back, an
// SSLBP command) may be sent when the line loses or garbles its replies, counted across
// every layer. ops owns it and hands it down where the links are built
// (timing.hpp, with every other count and timeout), so that the layers never multiply their resends:
//
// - Exchanges ops starts (Amp::with_retries, the transaction's reads and read-backs):
//   ops owns the loop and the links under it send each exchange once (the serial link's
//   PipelinedLinkOptions::retries and the passthrough's PassthroughOptions::lost_packet_resends
//   are 0). A lost read is sent at most `attempts` times, over serial and over Ethernet.
// - Exchanges of the Ethernet layers' own that ops never sees (SSLBP commands while a port
//   opens, read-only probes and polls of SSLBP's registers, IDROM reads): that layer
//   resends them, only where LBP16 makes it safe (packets without writes, SSLBP commands
//   that may run twice after a probe found them not run), at most `attempts` sends each.
//
// No layer resends an 8I20 write after a lost or garbled reply: ops answers it with a
// read-back and repeats the write only when the read-back shows that the card does not hold
// the value yet (ops::AmpCellAccess), within the same budget; a read-back that gets no
// answer either ends it with the error. Only the writes that switch NV access or RPC memory
// off are repeated as they are (Amp::with_retries, Amp::settle): twice is harmless.
//
// A card that stops answering for a while (a burst of line noise, a cable knocked, an
// 8I20 that reset itself and is back a few milliseconds later) is not given up on at once:
// when an exchange has spent its budget, ops asks the same harmless exchange again once per
// `probe_interval` until `silence_window` has passed since the card's first unanswered
// exchange, so that a transaction can learn what the card holds and finish (verified, or
// rolled back and verified) instead of ending uncertain. The window is per silence, not per
// exchange: once it has passed, later exchanges get only their budget until the card
// answers again. A write is never among the exchanges asked again (see above).
//
// Worst cases, per exchange and per command, are in README.md ("How long a command may
// take"); Amp::with_retries and Amp::wait_for_answer are where they are spent.
#pragma once

#include <chrono>

#include "ops/core/timing.hpp"

namespace i20::ops {

struct RetryPolicy {
  // Sends of one logical exchange in all, the first included (at least 1).
  unsigned attempts = timing::kAttempts;
  // How long a card that stopped answering is waited for, from its first unanswered
  // exchange; zero: an exchange gets its budget and no more.
  std::chrono::milliseconds silence_window = timing::kSilenceWindow;
  // How often a silent card is asked again within that window.
  std::chrono::milliseconds probe_interval = timing::kProbeInterval;
  // The operation's own deadline, from the moment its card is opened: after it no silence
  // window opens again and no exchange is sent more than once, so a network that keeps
  // almost answering (30% of datagrams reordered) cannot stretch a command without end.
  // What is left of a change then is finished on the shortest path (each cell's rollback
  // sent once, read back within the budget), and leaving NV access or RPC memory mode keeps
  // its silence window (Amp::settle): the card is never left in a mode to save time.
  std::chrono::milliseconds operation_deadline = timing::kOperationDeadline;
  // Resends a layer that owns the loop may add to the first send.
  unsigned resends() const { return attempts > 0 ? attempts - 1 : 0; }
};

}  // namespace i20::ops
