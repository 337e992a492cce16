// SPDX-License-Identifier: GPL-2.0-or-later
// The retry budget: how often one logical exchange with a card (a read, a read-back, an
// SSLBP command) may be sent when the line loses or garbles its replies, counted across
// every layer. ops owns it and hands it down where the links are built
// (link_options.hpp), so that the layers never multiply their resends:
//
// - Exchanges ops starts (Card::with_retries, the transaction's reads and read-backs):
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
// the value yet (ops::DeviceCardAccess), within the same budget; a read-back that gets no
// answer either ends it with the error. Only the writes that switch NV access or RPC memory
// off are repeated as they are (Card::with_retries, Card::settle): twice is harmless.
#pragma once

namespace i20::ops {

struct RetryPolicy {
  // Sends of one logical exchange in all, the first included (at least 1).
  unsigned attempts = 3;
  // Resends a layer that owns the loop may add to the first send.
  unsigned resends() const { return attempts > 0 ? attempts - 1 : 0; }
};

}  // namespace i20::ops
