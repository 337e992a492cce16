// SPDX-License-Identifier: GPL-2.0-or-later
// A bidirectional byte pipe with deadlines: what a serial port, a pseudo-terminal and
// the in-process simulator have in common. PipelinedLink builds LBP framing on top.
#pragma once

#include <chrono>
#include <span>
#include <string>
#include <vector>

#include "lbp/bytes.hpp"

namespace i20::link {

using Clock = std::chrono::steady_clock;

class ByteStream {
 public:
  virtual ~ByteStream() = default;

  // Writes all bytes (blocking until they are handed to the OS / device).
  virtual void write(lbp::ByteView bytes) = 0;
  // Reads at least one byte unless the deadline passes first; returns the count read
  // (0 means the deadline passed). Never blocks past the deadline.
  virtual std::size_t read_some(std::span<lbp::Byte> buffer, Clock::time_point deadline) = 0;
  // Drops whatever input is buffered and not read yet.
  virtual void discard_input() = 0;
  // Line rate in bits per second (for wire-time estimates and the command timeout).
  virtual unsigned baud() const = 0;
  // Device path or name, for messages.
  virtual std::string name() const = 0;
  // Set-up findings worth showing in verbose output (see Link::notes()).
  virtual std::vector<std::string> notes() const { return {}; }
};

}  // namespace i20::link
