// SPDX-License-Identifier: GPL-2.0-or-later
// Errors of the Ethernet transport. Transport failures are link::LinkError subclasses so
// that SslbpPassthroughLink honours the Link contract; what is wrong with the card
// itself (not a HostMot2 card, no SSERIAL module) is a plain i20::Error.
#pragma once

#include <string>

#include "link/link.hpp"

namespace i20::eth {

// The card answered, but not with what the request asks for (wrong size, impossible
// values). The reply is never acted upon.
class BadReplyError : public link::LinkError {
 public:
  using LinkError::LinkError;
};

// SSLBP flagged a failed transfer on the channel (DATA bit set); the message names the
// CS error bits in words.
class SslbpError : public link::LinkError {
 public:
  using LinkError::LinkError;
};

// Another host's packets reached the card during a passthrough exchange (space 6
// RXUDPCount moved beyond ours). Its DOITs would run whatever our CS and INTERFACE0 hold,
// and a DOIT of ours could be ignored while its result is taken for ours: the exchange's
// results are discarded rather than trusted.
class ForeignHostError : public link::LinkError {
 public:
  using LinkError::LinkError;
};

// A packet of ours that had been given up on reached the card between two later ones
// (fenced_transport.hpp): it ran on state the later ones share, so their results are
// discarded and every cell the command touched must be read back.
class LatePacketError : public link::LinkError {
 public:
  using LinkError::LinkError;
};

// The card is not what the target needs: no HostMot2 cookie, no SSERIAL module, no such
// port or channel, no 8I20 on the channel.
class DiscoveryError : public Error {
 public:
  using Error::Error;
};

}  // namespace i20::eth
