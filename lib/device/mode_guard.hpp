// RAII guards for the two card modes that must never outlive an operation: NV (EEPROM)
// access (docs/facts.md s2: NV mode goes back to RAM access on every path, errors included) and
// RPC memory access (manual: "The RPCMEM access flag must be clear for normal operation").
#pragma once

#include <string>

#include "lbp/command.hpp"
#include "link/link.hpp"

namespace i20::device {

class ModeGuard {
 public:
  // The guard is armed: the caller has sent (or is about to send, in the same batch)
  // the command that enters the mode. `leave` is the command that ends it.
  ModeGuard(link::Link& link, lbp::Command leave, std::string what);
  ~ModeGuard();
  ModeGuard(const ModeGuard&) = delete;
  ModeGuard& operator=(const ModeGuard&) = delete;

  // The leave command went out in a batch that completed: nothing left to do.
  void disarm() { armed_ = false; }
  // Leaves the mode now; throws CardStateError if the card does not confirm.
  void leave();

 private:
  link::Link& link_;
  lbp::Command leave_;
  std::string what_;
  bool armed_ = true;
};

}  // namespace i20::device
