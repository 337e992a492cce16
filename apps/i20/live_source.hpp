// Where live FAULT/STATUS/BUSV/TEMPERATURE come from, for `watch` and `faults`:
//  - a card reached by register reads (serial port, simulator, Ethernet passthrough);
//  - an Ethernet target: SSLBP normal mode, whose DOIT cycles carry bus voltage,
//    temperature, FAULT and STATUS in INTERFACE0/1 (8I20 manual) without knowing any
//    RAM address, and keep the 8I20's 40 ms watchdog fed while we watch.
#pragma once

#include <memory>
#include <string>

#include "context.hpp"
#include "faults_render.hpp"

namespace i20::cli {

class LiveSource {
 public:
  virtual ~LiveSource() = default;
  // One set of readings. Throws i20::Error when the card cannot be reached.
  virtual Readings read() = 0;
  // "8I20 on ..." target text, for messages.
  virtual std::string describe() = 0;
  // Drop the connection; the next read() opens it again.
  virtual void reconnect() = 0;
  // "normal mode (DOIT every 10 ms)" or "register reads": for the user.
  virtual std::string method() const = 0;
};

// Normal mode for Ethernet targets unless `registers_only`; register reads otherwise.
std::unique_ptr<LiveSource> make_live_source(Context& ctx, bool registers_only = false);

// True when the global options name an Ethernet target (--eth or an eth:// --port).
bool is_eth_target(const app::GlobalOptions& options);

}  // namespace i20::cli
