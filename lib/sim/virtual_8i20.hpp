// SPDX-License-Identifier: GPL-2.0-or-later
// The virtual 8I20: a strict, byte-level model of the card's LBP interface in front of
// a simulated amplifier. It is pure logic driven by the bytes and the time you give it,
// so tests control the clock; SimStream and i20sim add real time and transport.
//
// Use:
//   Virtual8i20 card(options, t0);
//   card.receive(bytes, t);        // bytes off the wire at time t (any split is fine)
//   card.advance(t);               // time passes: timeouts, EEPROM writes, faults tick
//   lbp::Bytes out = card.take_output();   // reply bytes due by the last time given
//   card.next_event();             // when advance() will next change something
// Time must not run backwards; an earlier time point is treated as the latest one seen.
//
// Choices where the manual is silent (documented in lib/sim/README.md):
//  - A command with a bad CRC is never executed and gets no reply; the CRC error count
//    (saturating at 255) and LBP status bit 0 go up. The host times out and resyncs.
//  - Every executed command is answered: reads with data + CRC, writes and RPCs without
//    reads with a single 0x00. 0xFE 0x5A is answered (0x00) before the reset; the card
//    then ignores input for `reset_time` and drops whatever was queued behind it.
//  - A write touching a read-only register (FAULT, STATUS, BUSV, TEMPERATURE, SWREVISION,
//    UNITNUMBER), an EEPROM address past the image, or flash (NV mode 2) is not
//    performed at all and sets LBP status bit 5; it is still answered.
//  - EEPROM writes take `eeprom_word_time` per 16-bit word touched; the card executes
//    nothing meanwhile (input queues in the receive buffer) and answers once the write
//    has completed.
//  - While the RPCMEM flag is set, addresses 0..RPCSize-1 reach the RPC table even in
//    NV mode; NV mode 1 routes every other data access to the EEPROM image.
#pragma once

#include <chrono>
#include <deque>
#include <filesystem>
#include <functional>
#include <optional>
#include <random>
#include <string>

#include "lbp/bytes.hpp"
#include "lbp/header.hpp"
#include "lbp/local.hpp"
#include "lbp/preparse.hpp"
#include "sim/amplifier.hpp"
#include "sim/framer.hpp"
#include "sim/injection.hpp"
#include "sim/register_map.hpp"
#include "sim/world.hpp"

namespace i20::sim {

inline constexpr unsigned kSetupBaud = 115200;
inline constexpr std::size_t kDefaultEepromBytes = 256;

struct DeviceOptions {
  RegisterMap map = RegisterMap::builtin();
  std::optional<std::filesystem::path> eeprom_file{};  // persistent EEPROM image, created if missing
  std::size_t eeprom_bytes = kDefaultEepromBytes;
  FramingMode mode = FramingMode::Setup;  // the W6 jumper: setup (115200) or operate (NVBAUDRATE)
  std::size_t rx_buffer_bytes = 128;
  Duration eeprom_word_time = std::chrono::milliseconds(2);
  Duration reset_time = std::chrono::milliseconds(1);  // deaf after 0xFE 0x5A
  lbp::Byte command_timeout = 255;                     // tenths of character times (25.5)
  lbp::Byte lbp_version = 3;                           // what 0xDA reports (not published)
  AmplifierSettings amplifier{};                       // operate_mode follows `mode`
  WorldSettings world{};
  Injection injection{};
  // The motor on this 8I20's outputs (operate mode drives it), if any.
  std::optional<motor::MotorParams> motor{};
};

// LBP interface registers (the local commands' state).
struct LbpRegisters {
  lbp::Byte status = 0;
  lbp::Byte crc_errors = 0;
  std::uint16_t address = 0;
  bool rpcmem = false;
  lbp::local::NvAccess nv_access = lbp::local::NvAccess::Ram;
  lbp::Byte command_timeout = 255;
  lbp::Byte leds = 0;
  lbp::Byte unit_id = 0;
};

struct DeviceStats {
  std::uint64_t commands_executed = 0;
  std::uint64_t bad_crc = 0;           // commands refused for their CRC
  std::uint64_t replies_dropped = 0;   // by injection
  std::uint64_t commands_ignored = 0;  // while muted (answer limit)
  std::uint64_t bytes_ignored = 0;     // while rebooting or powered off
  std::uint64_t eeprom_writes = 0;
  std::uint64_t resets = 0;                   // processor starts after the first: resets and power cycles
  std::uint64_t bytes_received = 0;           // every byte the host sent, heard or not
  std::uint64_t bytes_received_at_reset = 0;  // bytes_received when the card last reset
};

class Virtual8i20 {
 public:
  using Trace = std::function<void(const std::string&)>;

  // Powers the card up at `power_on` (EXTR sticky, NV -> working).
  explicit Virtual8i20(DeviceOptions options = {}, Clock::time_point power_on = Clock::time_point{});

  // Bytes received at `now`, in order.
  void receive(lbp::ByteView bytes, Clock::time_point now);
  // Lets time pass without input.
  void advance(Clock::time_point now);
  // Reply bytes due by the latest time given to receive()/advance().
  lbp::Bytes take_output();
  // The next time at which advance() has something to do (timeouts, EEPROM write done,
  // delayed reply, CLEARFAULT completion, watchdog), if any.
  std::optional<Clock::time_point> next_event() const;

  // Current line rate: 115200 in setup mode, NVBAUDRATE's rate in operate mode.
  unsigned baud() const;
  Clock::duration character_time() const;  // 10 bit times (8N1)

  // Power: off drops everything; power_cycle() powers up again from the EEPROM image.
  void power_off();
  void power_cycle(Clock::time_point now);
  bool powered() const { return powered_; }

  World& world() { return amplifier_.world(); }
  Injection& injection() { return injection_; }
  // Replaces the injection switches and restarts their random sequence from the seed.
  void set_injection(const Injection& injection);
  // The motor on this card's outputs (DeviceOptions::motor), or nullptr: its state
  // (mechanical angle in turns, speed, electrical angle, currents), its encoder and Hall
  // description and injected sensor faults, as of the latest time given to the card.
  const motor::Motor* motor() const { return amplifier_.motor(); }
  Amplifier& amplifier() { return amplifier_; }
  const Amplifier& amplifier() const { return amplifier_; }
  const LbpRegisters& lbp_registers() const { return lbp_; }
  const lbp::Bytes& rpc_table() const { return rpc_table_; }
  const DeviceStats& stats() const { return stats_; }
  bool eeprom_busy() const { return busy_until_.has_value(); }
  std::size_t rx_pending() const { return framer_.pending(); }
  bool framer_resyncing() const { return framer_.resyncing(); }
  std::size_t framer_dropped_bytes() const { return framer_.dropped_bytes(); }
  FramingMode mode() const { return options_.mode; }
  void set_trace(Trace trace) { trace_ = std::move(trace); }

 private:
  struct Outgoing {
    Clock::time_point release;
    lbp::Bytes bytes;
  };
  struct EepromWrite {
    std::size_t offset;
    lbp::Bytes data;
  };

  void service(Clock::time_point now);
  void finish_eeprom_write();
  void execute(const Framer::Frame& frame, Clock::time_point t);
  lbp::Bytes dispatch(const lbp::Bytes& command, Clock::time_point t, bool& reset_requested);
  lbp::Byte local_read(lbp::Byte command) const;
  bool local_write(lbp::Byte command, lbp::Byte data);
  lbp::Bytes data_access(const lbp::DataHeader& header, std::optional<std::uint16_t> address,
                         lbp::ByteView data, Clock::time_point t);
  lbp::Bytes run_rpc(unsigned number, lbp::ByteView stream, Clock::time_point t);
  lbp::Byte read_byte(std::uint16_t address) const;
  bool write_bytes(std::uint16_t address, lbp::ByteView data, Clock::time_point t);
  void emit(const lbp::Bytes& data, Clock::time_point t);
  void after_command(Clock::time_point t);
  void reset_processor(Clock::time_point t, std::uint16_t sticky_cause);
  void start_lbp(Clock::time_point t);
  void apply_command_timeout();
  void note_framer_events();
  bool deaf(Clock::time_point t) const;
  bool muted() const { return injection_.answer_limit && *injection_.answer_limit == 0; }
  double roll();
  void trace(const std::string& line) const {
    if (trace_) trace_(line);
  }

  DeviceOptions options_;
  Amplifier amplifier_;
  Framer framer_;
  LbpRegisters lbp_;
  lbp::Bytes rpc_table_;
  Injection injection_;
  std::mt19937_64 rng_;
  DeviceStats stats_;
  Trace trace_;

  Clock::time_point now_;
  bool powered_ = true;
  std::optional<Clock::time_point> deaf_until_;  // rebooting after a reset
  std::optional<Clock::time_point> busy_until_;  // EEPROM write in progress
  std::vector<EepromWrite> eeprom_pending_;
  std::deque<Outgoing> outbox_;
  std::uint64_t watchdog_bites_seen_ = 0;
};

}  // namespace i20::sim
