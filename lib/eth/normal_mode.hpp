// SPDX-License-Identifier: GPL-2.0-or-later
// Live status of 8I20s over SSLBP normal mode (8I20 manual, "NORMAL MODE OPERATION",
// "8I20 SPECIFIC INTERFACE REGISTER 0/1 DEFINITIONS"), for the CLI's watch and faults.
//
// Start: check that no other host runs the card (running_host.hpp; RunningHostError unless
// options.running_host.take_over), stop the port, normal start (0x900 | mask), check
// DATA, read each channel's unit number from INTERFACE0 (only valid before the first
// DOIT). A normal start is not a read: see kNormalStartEffect.
//
// Then a worker thread runs one DOIT cycle every `period` (default 10 ms, well under the
// 40 ms watchdog SSLBP programs into the 8I20), so the caller's own pace (printing,
// terminal) never lets the watchdog bite. One packet per cycle: read COMMAND, DATA,
// INTERFACE0/1 and CS of every channel (the data of the previous DOIT), write INTERFACE0
// = 0 (QSETPOINT 0, ANGLE 0: watch and faults never drive a motor; only `i20 commission`
// does, through DriveLoop in drive_loop.hpp), write COMMAND = 0x1000 |
// mask. Cycle packets are never resent: the next cycle replaces a lost one; a run of
// lost cycles fails the session.
//
// The caller polls latest() or blocks in wait_for_sample(). stop() (and the destructor)
// ends the thread and sends the SSLBP stop command.
//
// A session owns its SSERIAL port: the start stops whatever ran there (a passthrough
// link on the same port included), and the stop is a stop-all.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <string_view>
#include <thread>
#include <vector>

#include "eth/anything_io.hpp"
#include "eth/running_host.hpp"
#include "eth/sslbp_port.hpp"
#include "eth/target.hpp"
#include "eth/transport.hpp"
#include "eth/udp_client.hpp"

namespace i20::eth {

// What SSLBP's normal start does to every 8I20 it starts, for the user to hear before
// asking for one (8I20 manual, "8I20 DEVICE SPECIFIC SETUP"). Latched faults are gone
// afterwards: report them first (a setup-mode passthrough read leaves them alone).
inline constexpr std::string_view kNormalStartEffect =
    "a normal start clears the 8I20's latched faults, sets QSETPOINT to 0 A, enables its current "
    "loop and arms its 40 ms watchdog (8I20 manual, 8I20 DEVICE SPECIFIC SETUP)";

// The longest DOIT period: one lost cycle then still leaves the 8I20's 40 ms watchdog fed.
inline constexpr std::chrono::milliseconds kMaxDoitPeriod{20};

struct NormalModeOptions {
  UdpOptions udp;
  SslbpOptions sslbp;
  RunningHostCheck running_host;
  // DOIT period, at most kMaxDoitPeriod (check_doit_period).
  link::Given<std::chrono::milliseconds> period;
  // Consecutive cycles without a reply before the session gives up.
  link::Given<unsigned> max_missed_cycles;
  // Drive loop (commissioning): cycles of QSETPOINT 0 sent before the stop, so that the 8I20
  // sees the zero in a DOIT before its power stage is left to the watchdog.
  link::Given<unsigned> zero_cycles_before_stop;
};

struct ChannelSample {
  unsigned channel = 0;
  // INTERFACE0 MSW: "Bus voltage in 10s of mV" (8I20 manual, 8I20 SPECIFIC INTERFACE
  // REGISTER 0 DEFINITIONS).
  std::uint16_t bus_voltage = 0;
  // INTERFACE0 LSW: "Card Temperature in oC", whole degrees (same section; docs/facts.md
  // section 5). Not the TEMPERATURE parameter, which counts 0.01 C.
  std::uint16_t temperature = 0;
  std::uint16_t fault = 0;       // INTERFACE1 MSW
  std::uint16_t status = 0;      // INTERFACE1 LSW
  bool transfer_failed = false;  // the DOIT that produced this sample flagged the channel
  std::uint32_t cs = 0;

  double bus_volts() const { return bus_voltage / 100.0; }
  double temperature_celsius() const { return temperature; }
};

struct LiveStatus {
  using Clock = std::chrono::steady_clock;
  std::uint64_t sequence = 0;  // increases by one per published sample
  Clock::time_point taken{};
  std::vector<ChannelSample> channels{};
  std::uint64_t doits = 0;          // DOIT commands issued so far
  std::uint64_t late_cycles = 0;    // cycles that found the previous DOIT unfinished
  std::uint64_t missed_cycles = 0;  // cycles whose reply was lost
  // Longest time between two DOITs so far. Above 40 ms the 8I20's watchdog bites: the
  // host was starved (a loaded machine), not the protocol.
  std::chrono::microseconds max_doit_gap{0};

  const ChannelSample* channel(unsigned ch) const;
};

// The start every normal-mode user shares: identify the card, read its HostMot2 map, refuse
// a running host (unless options.running_host.take_over), stop the port, normal-start
// `mask` and read each channel's unit number. DiscoveryError (the port stopped again) when
// a channel does not start. The port refers to `bus`, which must outlive it.
struct NormalStart {
  HostMot2Info hostmot2;
  std::unique_ptr<SslbpPort> port;
  std::vector<std::pair<unsigned, std::uint32_t>> unit_numbers;
  HostActivity activity;
};
// Throws UsageError unless `period` is 1 ms to kMaxDoitPeriod.
void check_doit_period(std::chrono::milliseconds period);

NormalStart start_normal_mode(Lbp16Transport& bus, unsigned sserial_port, std::uint8_t mask,
                              const NormalModeOptions& options);

class NormalModeSession {
 public:
  // One channel, from the target.
  static std::unique_ptr<NormalModeSession> open(const EthTarget& target, NormalModeOptions options);
  // Several channels of one SSERIAL port.
  static std::unique_ptr<NormalModeSession> open(const HostPort& host_port, unsigned sserial_port,
                                                 std::uint8_t channel_mask, NormalModeOptions options);
  // Over any transport. Throws DiscoveryError when a channel does not start.
  NormalModeSession(std::unique_ptr<Lbp16Transport> bus, unsigned sserial_port, std::uint8_t channel_mask,
                    NormalModeOptions options);
  ~NormalModeSession();
  NormalModeSession(const NormalModeSession&) = delete;
  NormalModeSession& operator=(const NormalModeSession&) = delete;

  // INTERFACE0 after the start, before the first DOIT. UsageError for a channel not in
  // the session.
  std::uint32_t unit_number(unsigned channel) const;
  std::uint8_t channel_mask() const { return mask_; }
  // What the running-host check saw before the start.
  const HostActivity& host_activity() const { return activity_; }

  // The newest sample, nullopt until the first one. Rethrows the worker's failure.
  std::optional<LiveStatus> latest() const;
  // Blocks until a sample newer than the one this call returned last time. Throws
  // link::TimeoutError when none comes in time (at once once stopped: a sample not taken
  // before stop() goes with the session), or the worker's failure.
  LiveStatus wait_for_sample(std::chrono::milliseconds timeout);

  // Ends the cycles and stops the SSLBP port. Idempotent; the destructor calls it and
  // swallows errors, call it yourself to see them.
  void stop();
  bool running() const;
  std::string describe() const;

 private:
  struct Cycle;
  void worker();
  void run_cycle(const Cycle& cycle, std::uint64_t& consecutive_missed);
  void publish(LiveStatus status);
  void fail(std::exception_ptr error);

  std::unique_ptr<Lbp16Transport> bus_;
  std::unique_ptr<SslbpPort> port_;
  NormalModeOptions options_;
  std::uint8_t mask_;
  std::vector<std::pair<unsigned, std::uint32_t>> unit_numbers_{};
  HostActivity activity_{};

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<LiveStatus> latest_{};
  std::exception_ptr error_;
  bool stop_requested_ = false;
  bool stopped_ = false;
  std::uint64_t returned_sequence_ = 0;
  std::uint64_t doits_ = 0, late_ = 0, missed_ = 0;  // worker-only
  std::chrono::microseconds max_doit_gap_{0};
  std::optional<std::chrono::steady_clock::time_point> last_doit_{};
  std::thread thread_;
};

}  // namespace i20::eth
