// SPDX-License-Identifier: GPL-2.0-or-later
// Where i20sim's control lines come from besides stdin: a FIFO (--control PATH), created
// when missing and removed again if we created it, and a splitter that turns the bytes
// read from either into lines.
#pragma once

#include <string>
#include <vector>

#include "unique_fd.hpp"

namespace i20::sim::app {

// A FIFO we read control lines from. We also hold a writer open ourselves, so the FIFO
// never reports end-of-file when a shell's `echo ... > fifo` closes it, and a writer never
// blocks waiting for a reader. Throws ConfigError naming the path when it cannot be used.
class ControlFifo {
 public:
  explicit ControlFifo(const std::string& path);
  ~ControlFifo();
  ControlFifo(const ControlFifo&) = delete;
  ControlFifo& operator=(const ControlFifo&) = delete;
  int fd() const { return read_.get(); }

 private:
  std::string path_;
  bool created_ = false;
  UniqueFd read_, keep_open_;
};

// Bytes in, complete lines out ('\n' removed, '\r' too).
class LineSplitter {
 public:
  // Reads what `fd` has now. Returns the complete lines; sets `eof` at end of input.
  std::vector<std::string> read_from(int fd, bool& eof);

 private:
  std::string pending_;
};

}  // namespace i20::sim::app
