// SPDX-License-Identifier: GPL-2.0-or-later
// A host loop that DRIVES one 8I20 in SSLBP normal mode (8I20 manual, "NORMAL MODE
// OPERATION", "8I20 SPECIFIC INTERFACE REGISTER 0/1 DEFINITIONS") and reads the axis's
// feedback (HostMot2 quadrature counters, GPIO and InM inputs) in the same round trip: what
// commissioning needs, and what `watch` and `faults` must never do (they keep to
// NormalModeSession, which writes zeros).
//
// The caller is the loop: cycle() waits for the next period, then sends one packet that
// reads the previous DOIT's INTERFACE0/1 and every feedback register, writes INTERFACE0 =
// QSETPOINT (MSW) | ANGLE (LSW), re-arms the counters' index latches, and writes the DOIT.
// A caller that stops calling starves the 8I20's 40 ms watchdog, which then disables the
// power stage: the backstop if the tool dies. stop() (and the destructor) sends a few
// cycles of QSETPOINT 0 and stops the port.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "eth/normal_mode.hpp"

namespace i20::eth {

// Where the feedback sits, from the card's IDROM: what a DriveLoop reads each cycle.
struct FeedbackMap {
  struct Encoder {
    unsigned instance = 0;
    std::uint16_t count = 0;          // count register (count in bits 0-15)
    std::uint16_t latch_control = 0;  // latched count in 16-31, control bits in 0-15
  };
  // An input bit a Hall sensor may be wired to, named as LinuxCNC's hostmot2 names its pin.
  struct Input {
    std::size_t word = 0;  // index into FeedbackMap::input_words
    unsigned bit = 0;
    std::string hal_pin;  // "gpio.010.in", "inm.00.input-02" (after the board prefix)
  };
  std::vector<Encoder> encoders;
  std::vector<std::uint16_t> input_words;  // IOPort data and InM filtered-data registers
  std::vector<Input> inputs;               // GPIO pins no module owns, and InM inputs
  // The InM word and its control register: hostmot2 sets the control's global invert so
  // that an active input reads 1 (docs/virtual-feedback.md, "7I96S: the isolated inputs");
  // without it set, the data is inverted here so the inputs read as hostmot2 shows them.
  std::optional<std::size_t> inm_word;
  std::uint16_t inm_control = 0;
};

// Builds the map. IOPort pins that a module owns (an encoder's A/B/Z, SSERIAL, InM) are
// not Hall candidates: their levels move with their module.
FeedbackMap feedback_map(const HostMot2Info& info);

// One cycle's command: QSETPOINT (-32767..32767 = -MAXCURRENT..+MAXCURRENT) and ANGLE
// (0..65535 = one electrical turn).
struct DriveSetpoint {
  std::int16_t qsetpoint = 0;
  std::uint16_t angle = 0;
};

struct EncoderReading {
  std::uint16_t count = 0;
  std::uint32_t latch_control = 0;
  bool index_latched = false;  // an index event since the latch was armed last cycle
  std::uint16_t latched = 0;   // the latched count (valid when index_latched)
};

struct DriveReading {
  std::chrono::steady_clock::time_point taken{};
  // When the host sent the packet, on its own clock (a run's time limits count from it; the
  // readings' time is the card's, below).
  std::chrono::steady_clock::time_point sent{};
  // The card's free-running microsecond timer as it read the encoders (wraps every 65.536 ms):
  // the readings' own time, whatever the host or the network did with the packet.
  std::uint16_t card_microseconds = 0;
  // false: INTERFACE0/1 are not this DOIT's (the previous DOIT had not finished, or this is
  // the first one); the feedback registers are current either way.
  bool fresh = true;
  // This cycle's QSETPOINT and ANGLE reach the 8I20: the card's previous DOIT had finished
  // when the packet came (a busy card ignores the DOIT; the last one taken stays in effect).
  bool command_taken = true;
  std::uint16_t bus_voltage = 0;  // 10 mV
  std::uint16_t fault = 0;
  std::uint16_t status = 0;
  bool transfer_failed = false;
  std::vector<EncoderReading> encoders;  // in FeedbackMap::encoders order
  std::vector<std::uint32_t> input_words;
};

// DOIT timing: gaps between consecutive DOITs the card took.
struct DoitStats {
  std::uint64_t doits = 0;
  std::uint64_t late = 0;    // the previous DOIT was still running: ours was not taken
  std::uint64_t missed = 0;  // replies lost
  std::vector<std::chrono::microseconds> gaps;

  std::chrono::microseconds percentile(double p) const;  // 0 when there is no gap
  std::chrono::microseconds worst() const;
};

// While it lives, the calling thread runs SCHED_FIFO at a low priority (10), as LinuxCNC runs
// its servo thread, where the system allows it (root, or CAP_SYS_NICE): a loaded machine
// then still sends the DOITs on time, well inside the 8I20's 40 ms watchdog. Elsewhere it
// changes nothing and granted() says so. The loop sleeps every period, so it cannot starve
// the machine.
class RealtimePriority {
 public:
  RealtimePriority();
  ~RealtimePriority();
  RealtimePriority(const RealtimePriority&) = delete;
  RealtimePriority& operator=(const RealtimePriority&) = delete;
  bool granted() const { return granted_; }

 private:
  int old_policy_ = 0;
  int old_priority_ = 0;
  bool granted_ = false;
};

class DriveLoop {
 public:
  // Over any transport; starts `channel` of SSERIAL `sserial_port` (start_normal_mode).
  DriveLoop(std::unique_ptr<Lbp16Transport> bus, unsigned sserial_port, unsigned channel,
            NormalModeOptions options);
  static std::unique_ptr<DriveLoop> open(const EthTarget& target, NormalModeOptions options);
  ~DriveLoop();
  DriveLoop(const DriveLoop&) = delete;
  DriveLoop& operator=(const DriveLoop&) = delete;

  // Waits for the next period, then one round trip. Throws link::TimeoutError after
  // options.max_missed_cycles lost replies in a row (the 8I20 watchdog has then bitten).
  DriveReading cycle(DriveSetpoint setpoint);
  // Packets that reached the card since the start and were not ours (one read-only packet).
  std::uint32_t foreign_packets();
  // QSETPOINT 0 for a few cycles, then the port stopped. Idempotent.
  void stop();

  const FeedbackMap& feedback() const { return map_; }
  const HostMot2Info& hostmot2() const { return hostmot2_; }
  const DoitStats& stats() const { return stats_; }
  std::uint32_t unit_number() const { return unit_number_; }
  std::chrono::milliseconds period() const { return options_.period; }
  std::string describe() const;

 private:
  std::vector<lbp::lbp16::Command> packet(DriveSetpoint setpoint) const;
  DriveReading decode(const std::vector<lbp::Bytes>& parts);

  std::unique_ptr<Lbp16Transport> bus_;
  NormalModeOptions options_;
  unsigned channel_;
  HostMot2Info hostmot2_;
  std::unique_ptr<SslbpPort> port_;
  HostActivity activity_;
  FeedbackMap map_;
  std::uint32_t unit_number_ = 0;
  DoitStats stats_;
  unsigned consecutive_missed_ = 0;
  bool latches_armed_ = false;
  bool stopped_ = false;
  std::chrono::steady_clock::time_point next_{};
  std::optional<std::chrono::steady_clock::time_point> last_doit_{};
};

}  // namespace i20::eth
