// SPDX-License-Identifier: GPL-2.0-or-later
// The one narrow seam between the device layer and every transport:
// "execute these LBP commands, give me their replies".
//
// Implementations: the serial port (PipelinedLink over SerialStream), the in-process
// simulator (PipelinedLink over the simulator's stream), and Ethernet through a
// 7I96S/7I92T (SSLBP setup-mode passthrough).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "error/error.hpp"
#include "lbp/command.hpp"

namespace i20::link {

// The transport failed. `completed` says how many commands of the batch got a valid
// reply before the failure, so callers that must know the card's state (NV writes,
// batch apply) can tell what took effect. Commands after `completed` may or may not
// have reached the card: a write whose reply was lost may still have been executed.
class LinkError : public Error {
 public:
  LinkError(const std::string& message, std::size_t completed = 0) : Error(message), completed_(completed) {}
  std::size_t completed() const { return completed_; }

 private:
  std::size_t completed_;
};

// No (complete) reply within the deadline.
class TimeoutError : public LinkError {
 public:
  using LinkError::LinkError;
};

// The operation's time was up (link/wait_bound.hpp) before this exchange was sent: nothing
// of it reached the card, so no layer probes for it as for a lost reply (not a
// TimeoutError). `completed` counts the commands of the batch that were answered before.
class OutOfTime : public LinkError {
 public:
  using LinkError::LinkError;
};

// A reply arrived with a wrong CRC, or the card flagged our command as corrupt.
class CrcError : public LinkError {
 public:
  using LinkError::LinkError;
};

// More reply bytes arrived than the batch's commands account for: the reply framing
// was lost (a stale or duplicated byte), so no reply of the batch can be trusted and
// `completed` is 0 even if every reply passed its CRC.
class FramingError : public LinkError {
 public:
  using LinkError::LinkError;
};

// The transport cannot carry this command (e.g. an 8-byte access through SSLBP).
class UnsupportedCommand : public LinkError {
 public:
  using LinkError::LinkError;
};

class Link {
 public:
  virtual ~Link() = default;

  // Executes the commands in order and returns the data of each reply (CRC checked and
  // removed), one entry per command. Throws LinkError (or a subclass) on failure, after
  // resynchronising so that the next call starts clean.
  virtual std::vector<lbp::Bytes> execute(std::span<const lbp::Command> batch) = 0;

  // Where this link goes, for messages: "/dev/ttyUSB0", "simulator", "eth 10.0.0.2 ch 0".
  virtual std::string describe() const = 0;

  // What the transport found out while setting up ("low-latency mode on", "latency timer
  // not writable: ..."), for verbose output. The library never prints.
  virtual std::vector<std::string> notes() const { return {}; }

  // The largest data size (bytes) one command may carry on this transport: 8 on a
  // serial line, 4 through SSLBP's 32-bit INTERFACE0 register.
  virtual std::size_t max_data_bytes() const { return 8; }

  // Convenience for a batch of one.
  lbp::Bytes execute_one(const lbp::Command& command) {
    return execute(std::span<const lbp::Command>(&command, 1)).front();
  }
};

}  // namespace i20::link
