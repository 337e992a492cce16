// SPDX-License-Identifier: GPL-2.0-or-later
// A test utility: a UDP proxy between LBP16 clients and a card that delays, duplicates
// and drops datagrams, the way a congested switch or a busy host can. Tests and the soak
// put it between the tool and the virtual card to prove that a late or repeated request
// never turns into a false "done".
//
//   ethsim::NetworkFaults faults{.seed = 7, .delay_share = 0.1};
//   ethsim::FaultyNetwork proxy(card.address(), faults);   // listens on 127.0.0.1:<free>
//   run i20 --eth proxy.address() ...;
//   proxy.wait_idle(5s);                                   // everything held back delivered
//
// Each client endpoint gets a socket of its own towards the card, so every reply goes back
// to the socket that sent its request (a NAT would do the same). The fault drawn for each
// datagram depends only on the seed, the direction and the datagram's index in that
// direction: a run is repeatable as far as the tool sends the same datagrams.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "eth/target.hpp"

namespace i20::ethsim {

struct NetworkFaults {
  std::uint64_t seed = 1;
  // Shares (0..1) of datagrams, drawn per datagram and per direction.
  double delay_share = 0.0;      // held back by a delay in [min_delay, max_delay]
  double duplicate_share = 0.0;  // sent twice, the copy after a delay in [0, max_delay]
  double drop_share = 0.0;       // never delivered
  double truncate_share = 0.0;   // delivered cut short, at a random length (at least 1 byte shorter)
  // Held until the next datagram of the same direction has gone by, then delivered after it
  // (a reordering switch or proxy); one that nothing follows within max_delay goes then.
  double reorder_share = 0.0;
  // Held until the next datagram of either direction has passed, then delivered right after
  // it, however long that takes (issue 40's proxy): a held request is answered only after
  // the tool's next datagram, a held reply arrives only after the tool has sent again. One
  // is held at a time; release_held() delivers it when nothing follows (the end of a run).
  double hold_share = 0.0;
  std::chrono::milliseconds min_delay{80};
  std::chrono::milliseconds max_delay{400};
  bool requests = true;  // spoil tool-to-card datagrams
  bool replies = true;   // spoil card-to-tool datagrams
};

struct NetworkStats {
  std::uint64_t requests = 0, replies = 0;  // datagrams received from either side
  std::uint64_t delayed = 0, duplicated = 0, dropped = 0, truncated = 0, reordered = 0, held = 0;
};

class FaultyNetwork {
 public:
  FaultyNetwork(eth::HostPort host_port, NetworkFaults faults);
  ~FaultyNetwork();
  FaultyNetwork(const FaultyNetwork&) = delete;
  FaultyNetwork& operator=(const FaultyNetwork&) = delete;

  // "127.0.0.1:PORT": where the tool should send.
  std::string address() const;
  // Waits until a full pass over the sockets, begun after this call, found nothing to
  // read and nothing held back: every datagram sent before the call (a delayed or
  // duplicated one too) has been delivered. False when `limit` passed first.
  bool wait_idle(std::chrono::milliseconds limit) const;
  NetworkStats stats() const;
  // The end of a run: delivers the datagram hold_share holds, if any, as if the next one had
  // passed, and holds nothing more (the card's reply to a request released here would
  // otherwise be held in turn, with nothing left to follow it: CI saw wait_idle() give up so).
  // A run is judged after every datagram it sent reached its end.
  void release_held();
  // From the next datagram on, these faults (the soak turns them on once the card is open
  // and off again when the fault heals).
  void set_faults(const NetworkFaults& faults);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::thread thread_;
};

}  // namespace i20::ethsim
