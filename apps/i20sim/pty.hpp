// SPDX-License-Identifier: GPL-2.0-or-later
// A pseudo-terminal pair for serving the simulator as if it were a serial port. The
// slave side is put in raw mode so every byte passes untouched, and we keep our own
// slave descriptor open so the pty does not hang up when a client disconnects.
#pragma once

#include <string>

#include "unique_fd.hpp"

namespace i20::sim::app {

class Pty {
 public:
  // Throws sim::ConfigError naming the failing call if no pty can be created.
  Pty();

  int master() const { return master_.get(); }
  const std::string& slave_path() const { return slave_path_; }

 private:
  UniqueFd master_;
  UniqueFd slave_;
  std::string slave_path_;
};

}  // namespace i20::sim::app
